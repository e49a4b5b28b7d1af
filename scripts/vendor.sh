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

# sha256 of the npm tarballs (npm itself also checks the registry's sha512
# integrity when it downloads them).
NIPPLEJS_TGZ_SHA256="09f50689ef1169b2bf03c8f6263b10981cd5dc572bcbc007133e8ccdff0352a2"
MAPLIBRE_TGZ_SHA256="b84d7fdf7fba5922fd3fff9a92733936c7a03b99165afc6c84f41c311bdbfa9d"
UPLOT_TGZ_SHA256="4b8a8191e425658e3ea8c8c1314b0fc679c861ee3a1af2b20c7b16ba50b5133d"
SWAGGER_UI_TGZ_SHA256="1b8e891893404ea4c3558b6a87e2a3e494e7eedba41168c2ece5800a391a6ea6"
GRIDSTACK_TGZ_SHA256="dad337eb31dccca66781783efaefd29a65a10fc067145607c95ff39a9e94a84b"

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
GRIDSTACK_FILES=(
  "dist/gridstack-all.js    gridstack-all.js    e12690e8e671d752c8007993967830e6a4b8bcfb2787ac85d1100dff765460b4"
  "dist/gridstack.min.css   gridstack.min.css   74efc82159c5e8d28cb2cebd9f912be9d728bb07fa83896a6b62f4a843207126"
  "LICENSE                  LICENSE             28d28a6e0b5c6ebca8759b162a644c31cea28aab591060c0d95c7737d8456764"
)

REPO_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENDOR_DIR="$REPO_ROOT/static/vendor"

die() { echo "vendor.sh: $*" >&2; exit 1; }

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
    install -m 0644 "$work/unpacked/package/$src" "$work/stage/$dst"
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
  [[ $rc -eq 0 ]] && echo "vendor.sh: all vendored files match their pinned sha256"
  exit "$rc"
elif [[ $# -gt 0 ]]; then
  die "unknown argument: $1 (usage: scripts/vendor.sh [--check])"
fi

command -v npm >/dev/null || die "npm not found"
TMP="$(mktemp -d "${TMPDIR:-/tmp}/rover-vendor.XXXXXX")"
trap 'rm -rf "$TMP"' EXIT

vendor_pkg nipplejs "$NIPPLEJS_VERSION" "$NIPPLEJS_TGZ_SHA256" "${NIPPLEJS_FILES[@]}"
vendor_pkg maplibre-gl "$MAPLIBRE_VERSION" "$MAPLIBRE_TGZ_SHA256" "${MAPLIBRE_FILES[@]}"
vendor_pkg uplot "$UPLOT_VERSION" "$UPLOT_TGZ_SHA256" "${UPLOT_FILES[@]}"
vendor_pkg swagger-ui-dist "$SWAGGER_UI_VERSION" "$SWAGGER_UI_TGZ_SHA256" "${SWAGGER_UI_FILES[@]}"
vendor_pkg gridstack "$GRIDSTACK_VERSION" "$GRIDSTACK_TGZ_SHA256" "${GRIDSTACK_FILES[@]}"
echo "vendor.sh: done"
