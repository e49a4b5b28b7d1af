#!/usr/bin/env bash
# Vendor the browser libraries that rover_web serves from static/vendor/.
#
# The GUI must load nothing from the internet at run time, so the JS/CSS it
# needs is copied into the repo from the npm registry by this script.
# Versions and the sha256 of every copied file are pinned below; the script
# refuses to install anything whose checksum differs.
#
# Usage:
#   scripts/vendor.sh           # npm pack the pinned versions, copy, verify
#   scripts/vendor.sh --check   # only verify the files already in the repo
#                               # (no network needed)
#
# Idempotent: re-running replaces static/vendor/<name>-<version>/ with
# byte-identical files. To upgrade, change a version below, run the script
# once, read the "sha256 mismatch" output, and update the pinned sums and
# static/vendor/README.md after reviewing the new files.
set -euo pipefail

NIPPLEJS_VERSION="0.10.2"
MAPLIBRE_VERSION="5.24.1"
UPLOT_VERSION="1.6.32"
SWAGGER_UI_VERSION="5.35.0"
GRIDSTACK_VERSION="14.1.0"
THREE_VERSION="0.187.0"
URDF_LOADER_VERSION="0.13.1"
AXE_CORE_VERSION="4.14.1"  # tests only (tests/browser/test_a11y_audit.py injects it); no page loads it

# sha256 of the npm tarballs (npm itself also checks the registry's sha512
# integrity when it downloads them).
NIPPLEJS_TGZ_SHA256="09f50689ef1169b2bf03c8f6263b10981cd5dc572bcbc007133e8ccdff0352a2"
MAPLIBRE_TGZ_SHA256="b84d7fdf7fba5922fd3fff9a92733936c7a03b99165afc6c84f41c311bdbfa9d"
UPLOT_TGZ_SHA256="4b8a8191e425658e3ea8c8c1314b0fc679c861ee3a1af2b20c7b16ba50b5133d"
SWAGGER_UI_TGZ_SHA256="1b8e891893404ea4c3558b6a87e2a3e494e7eedba41168c2ece5800a391a6ea6"
GRIDSTACK_TGZ_SHA256="dad337eb31dccca66781783efaefd29a65a10fc067145607c95ff39a9e94a84b"
# three's npm package ships no minified build (0.187.0's build/ has none) and urdf-loader has none:
# their ES modules are minified here by esbuild (the minifier Vite uses), its Linux x64 binary from
# npm, pinned. Its output is deterministic for a version, so the sums of the
# minified files are pinned like any other.
ESBUILD_VERSION="0.28.2"
ESBUILD_TGZ_SHA256="9573bb2233aab0f9ea7647d5cca9726113cc1768de61d66b17267f4db84488f6"  # @esbuild/linux-x64
THREE_TGZ_SHA256="ff540832ded0cfe919764d24a3d88f3e2a05f23303f876423e4f893841e90728"
URDF_LOADER_TGZ_SHA256="19909aad681a1dfb5e4820aaf8369f6ff0837ae91dbb664f47895fe2d64f0b83"
AXE_CORE_TGZ_SHA256="e6b0ce02b84d892e2e33e403485e7f3d6c29e2be6df65daf44d89ba564139745"

# "<path inside the package>  <name in static/vendor/...>  <sha256>"
NIPPLEJS_FILES=(
  "dist/nipplejs.js      nipplejs.js      b6a612a11381a67a0f0c16166448183e1c160609d370713a1aa5625d1c087253"
  "LICENSE               LICENSE          c2b08e655eae157edbeced89a20f684ff83b588f05813332440f7ccde09a3e33"
)
MAPLIBRE_FILES=(
  "dist/maplibre-gl.js   maplibre-gl.js   a9c9e2aa36d4d5b63b131f27c1272f1a28883eeecc0eddd1e0dbfae4033bc7c9"
  "dist/maplibre-gl.css  maplibre-gl.css  ab1e70d59ec40465bae7e7030da2f3ccf28133fd502e62bd598eefbadfd7a732"
  "LICENSE.txt           LICENSE.txt      ee5fc05a0677eaf69601d2c7db0d9ecd6cc27c3abc1d0733bc9ed34707cf8ef2"
)
UPLOT_FILES=(
  "dist/uPlot.iife.min.js  uPlot.iife.min.js  19c8d4c6ad88929a79f4ae49d6f7161566dfd0ba3d15cc495e974f787eb78f1f"
  "dist/uPlot.min.css      uPlot.min.css      df630c6a8d6f8eeaff264b50f73ce5b114f646ffd9a0bb74f049b0a00135fa04"
  "LICENSE                 LICENSE            8f989229699b4fe2f1a0432d0e9edc338a8a911e250e2d1b01ecd770a5f5b1bd"
)
SWAGGER_UI_FILES=(
  "swagger-ui-bundle.js  swagger-ui-bundle.js  e6a898692f2d768e807c3ba4626068a69a2c5dd960dd6c76f3e4d3a3de180af2"
  "swagger-ui.css        swagger-ui.css        5ed08757e53da3e026d6cbecc61fe5d43585c9560b302d534ad56692519a273d"
  "LICENSE               LICENSE               cfc7749b96f63bd31c3c42b5c471bf756814053e847c10f3eb003417bc523d30"
  "NOTICE                NOTICE                0d20d1adef18aee3f40dd258172155521ce702ac445cb5f7b7d60ed32dad2fb2"
)
# The dashboard editor's drag and resize (docs/dashboards.md says why gridstack): the UMD bundle with
# its drag-and-drop, which sets window.GridStack, and its stylesheet.
AXE_CORE_FILES=(
  "axe.min.js  axe.min.js  29348999450cdf2849a8e70b7912fc2da85a849da39c0d0d5394f51d4a9ed95c"
  "LICENSE     LICENSE     af175b9d96ee93c21a036152e1b905b0b95304d4ae8c2c921c7609100ba8df7e"
)
GRIDSTACK_FILES=(
  "dist/gridstack-all.js    gridstack-all.js    e12690e8e671d752c8007993967830e6a4b8bcfb2787ac85d1100dff765460b4"
  "dist/gridstack.min.css   gridstack.min.css   74efc82159c5e8d28cb2cebd9f912be9d728bb07fa83896a6b62f4a843207126"
  "LICENSE                  LICENSE             28d28a6e0b5c6ebca8759b162a644c31cea28aab591060c0d95c7737d8456764"
)

# The 3D view (docs/view3d.md): three.js's ES modules, the addons it needs, and urdf-loader. These are
# ES modules that import the bare name 'three'; rewrite_imports points those imports at the vendored
# files, relative, and minify (esbuild, above) makes the .min.js each is served as, its relative imports
# pointed at the other .min.js files and its @license comments kept; the sums below are of those files.
THREE_FILES=(
  "build/three.module.js                              three.module.min.js                  36dc3a9cfb7765751181533d6806dad99fa4ecbc894669351f693065d9f3cedc"
  "build/three.core.js                                three.core.min.js                    04750c60541ce68acf84ea72bdaea4b2dc7696b0501d36faeaa9d1d0cc63ba78"
  "LICENSE                                            LICENSE                              8b378ebe60e2fe500158cb0ac71cb5e8b7d92953c2abcc63a0eb90499653b5bc"
  "examples/jsm/controls/OrbitControls.js             addons/controls/OrbitControls.min.js d0eeeabe122b7ff6842304601e19699f3931b8eb3d94a8bb52e847a3eb6f921b"
  "examples/jsm/loaders/STLLoader.js                  addons/loaders/STLLoader.min.js      02956604f598654cf6df628d0226561e9762ddbd437786d9cd3e4ec781c43353"
  "examples/jsm/loaders/OBJLoader.js                  addons/loaders/OBJLoader.min.js      2a0ddd2f7230027510ce0300d0d0ec3e2a085b63c0e3b1b90a6117835829da4e"
  "examples/jsm/loaders/TGALoader.js                  addons/loaders/TGALoader.min.js      0f0859dadfc6ea5b1753c8d6d985f9e5f13822ffb8d21741e65457c847b8f838"
  "examples/jsm/loaders/ColladaLoader.js              addons/loaders/ColladaLoader.min.js  6b0a01936c039ed5e74078438aac7e8d3042a0d8e24ce56304bb686cb6fc2284"
  "examples/jsm/loaders/collada/ColladaParser.js      addons/loaders/collada/ColladaParser.min.js   edc26b748a02788459744c3d7051e18f921cc7f08580040a018d35940b840f13"
  "examples/jsm/loaders/collada/ColladaComposer.js    addons/loaders/collada/ColladaComposer.min.js 3f18c230de10ba8136af3f59306f371a269224363a4d5499d3aae49627db354d"
)
# urdf-loader's tarball carries no licence file; package.json says Apache-2.0, whose text is added from
# Debian's /usr/share/common-licenses/Apache-2.0 (see static/vendor/README.md).
URDF_LOADER_FILES=(
  "src/URDFLoader.js    URDFLoader.min.js    da097ac4c7e99d6a192d448ee755160f8718f07e3150326a4475dd61cabd9979"
  "src/URDFClasses.js   URDFClasses.min.js   4fa65af7fa612935ec75596fded700a231fa23fa6474c2b182bf635343d2b733"
  "package.json         package.json     d4134ad13b0a5a1abd7ee1d6178c1f55dcfcfa0bf61b090e46620b5e05c27bb2"
)

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENDOR_DIR="$REPO_ROOT/static/vendor"

die() { echo "vendor.sh: $*" >&2; exit 1; }

# rewrite_imports FILE PATH_IN_PACKAGE_DIR NPM_NAME: a bare 'three' (or 'three/examples/jsm/...') import made relative.
rewrite_imports() {
  local file="$1" dst="$2" name="$3" up="" three
  local depth="${dst//[^\/]/}"
  for ((i = 0; i < ${#depth}; i++)); do up="../$up"; done
  case "$file" in *.js) ;; *) return 0 ;; esac
  if [[ "$name" == urdf-loader ]]; then three="${up}../three-$THREE_VERSION/"; else three="${up:-./}"; fi
  sed -i -E "s#from 'three'#from '${three}three.module.js'#; s#from 'three/examples/jsm/#from '${three}addons/#" "$file"
}

# minify FILE: esbuild's minified form of an ES module, in place; its relative imports (the vendored
# modules beside it) point at their .min.js names.
minify() {
  local file="$1"
  sed -i -E "s#(from '\.{1,2}/[^']*)\.js'#\1.min.js'#g" "$file"
  "$ESBUILD" --minify --legal-comments=inline --charset=utf8 --log-level=warning "$file" --outfile="$file.min" \
    || die "esbuild could not minify $file"
  mv "$file.min" "$file"
}

# fetch_esbuild: the pinned esbuild binary (npm's @esbuild/linux-x64, its tarball's sum checked) in $TMP.
fetch_esbuild() {
  [[ "$(uname -s)-$(uname -m)" == Linux-x86_64 ]] || die "the pinned esbuild is Linux x86_64's (minify needs it)"
  mkdir -p "$TMP/esbuild"
  (cd "$TMP/esbuild" && npm pack --loglevel=error "@esbuild/linux-x64@$ESBUILD_VERSION" >/dev/null) \
    || die "npm pack @esbuild/linux-x64@$ESBUILD_VERSION failed"
  [[ "$(sha256_of "$TMP/esbuild/esbuild-linux-x64-$ESBUILD_VERSION.tgz")" == "$ESBUILD_TGZ_SHA256" ]] \
    || die "tarball sha256 mismatch for @esbuild/linux-x64@$ESBUILD_VERSION"
  tar -xzf "$TMP/esbuild/esbuild-linux-x64-$ESBUILD_VERSION.tgz" -C "$TMP/esbuild"
  ESBUILD="$TMP/esbuild/package/bin/esbuild"
}

sha256_of() { sha256sum "$1" | cut -d' ' -f1; }

# verify_dir DIR ENTRY... : check every listed file in DIR against its sum.
verify_dir() {
  local dir="$1"; shift
  local entry src dst sum actual bad=0
  for entry in "$@"; do
    read -r src dst sum <<<"$entry"
    if [[ ! -f "$dir/$dst" ]]; then
      echo "missing: $dir/$dst" >&2; bad=1; continue
    fi
    actual="$(sha256_of "$dir/$dst")"
    if [[ "$actual" != "$sum" ]]; then
      echo "sha256 mismatch: $dir/$dst" >&2
      echo "  expected $sum" >&2
      echo "  actual   $actual" >&2
      bad=1
    fi
  done
  return "$bad"
}

# vendor_pkg NPM_NAME VERSION TGZ_SHA256 ENTRY...
vendor_pkg() {
  local name="$1" version="$2" tgz_sum="$3"; shift 3
  local dest="$VENDOR_DIR/$name-$version"
  local work="$TMP/$name"
  local entry src dst sum tgz

  mkdir -p "$work/pack" "$work/unpacked" "$work/stage"
  echo "npm pack $name@$version"
  # npm's file listing goes to stderr; keep it out of the way but show errors.
  (cd "$work/pack" && npm pack --loglevel=error "$name@$version" >/dev/null) \
    || die "npm pack $name@$version failed"
  tgz="$(cd "$work/pack" && ls -- *.tgz 2>/dev/null | head -n 1)"
  [[ -n "$tgz" && -f "$work/pack/$tgz" ]] || die "npm pack $name@$version produced no tarball"
  [[ "$(sha256_of "$work/pack/$tgz")" == "$tgz_sum" ]] \
    || die "tarball sha256 mismatch for $name@$version: $(sha256_of "$work/pack/$tgz")"
  tar -xzf "$work/pack/$tgz" -C "$work/unpacked"

  for entry in "$@"; do
    read -r src dst sum <<<"$entry"
    [[ -f "$work/unpacked/package/$src" ]] || die "$name@$version has no $src"
    mkdir -p "$(dirname "$work/stage/$dst")"
    install -m 0644 "$work/unpacked/package/$src" "$work/stage/$dst"
    if [[ "$name" == three || "$name" == urdf-loader ]]; then rewrite_imports "$work/stage/$dst" "$dst" "$name"; fi
    if [[ "$dst" == *.min.js && "$src" != *.min.js ]]; then minify "$work/stage/$dst"; fi
  done
  verify_dir "$work/stage" "$@" || die "$name@$version: checksum verification failed, repo left untouched"

  # Replace the versioned directory only after everything verified.
  mkdir -p "$VENDOR_DIR"
  rm -rf "$dest.tmp"
  cp -a "$work/stage" "$dest.tmp"
  rm -rf "$dest"
  mv "$dest.tmp" "$dest"
  verify_dir "$dest" "$@" || die "$dest: verification after copy failed"
  echo "  -> ${dest#"$REPO_ROOT"/} ok"
}

if [[ "${1:-}" == "--check" ]]; then
  rc=0
  verify_dir "$VENDOR_DIR/nipplejs-$NIPPLEJS_VERSION" "${NIPPLEJS_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/maplibre-gl-$MAPLIBRE_VERSION" "${MAPLIBRE_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/uplot-$UPLOT_VERSION" "${UPLOT_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/swagger-ui-dist-$SWAGGER_UI_VERSION" "${SWAGGER_UI_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/gridstack-$GRIDSTACK_VERSION" "${GRIDSTACK_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/three-$THREE_VERSION" "${THREE_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/urdf-loader-$URDF_LOADER_VERSION" "${URDF_LOADER_FILES[@]}" || rc=1
  verify_dir "$VENDOR_DIR/axe-core-$AXE_CORE_VERSION" "${AXE_CORE_FILES[@]}" || rc=1
  [[ $rc -eq 0 ]] && echo "vendor.sh: all vendored files match their pinned sha256"
  exit "$rc"
elif [[ $# -gt 0 ]]; then
  die "unknown argument: $1 (usage: scripts/vendor.sh [--check])"
fi

command -v npm >/dev/null || die "npm not found"
TMP="$(mktemp -d "${TMPDIR:-/tmp}/rover-vendor.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT
fetch_esbuild

vendor_pkg nipplejs "$NIPPLEJS_VERSION" "$NIPPLEJS_TGZ_SHA256" "${NIPPLEJS_FILES[@]}"
vendor_pkg maplibre-gl "$MAPLIBRE_VERSION" "$MAPLIBRE_TGZ_SHA256" "${MAPLIBRE_FILES[@]}"
vendor_pkg uplot "$UPLOT_VERSION" "$UPLOT_TGZ_SHA256" "${UPLOT_FILES[@]}"
vendor_pkg swagger-ui-dist "$SWAGGER_UI_VERSION" "$SWAGGER_UI_TGZ_SHA256" "${SWAGGER_UI_FILES[@]}"
vendor_pkg gridstack "$GRIDSTACK_VERSION" "$GRIDSTACK_TGZ_SHA256" "${GRIDSTACK_FILES[@]}"
vendor_pkg three "$THREE_VERSION" "$THREE_TGZ_SHA256" "${THREE_FILES[@]}"
vendor_pkg urdf-loader "$URDF_LOADER_VERSION" "$URDF_LOADER_TGZ_SHA256" "${URDF_LOADER_FILES[@]}"
vendor_pkg axe-core "$AXE_CORE_VERSION" "$AXE_CORE_TGZ_SHA256" "${AXE_CORE_FILES[@]}"
install -m 0644 /usr/share/common-licenses/Apache-2.0 "$VENDOR_DIR/urdf-loader-$URDF_LOADER_VERSION/LICENSE"
echo "vendor.sh: done"
