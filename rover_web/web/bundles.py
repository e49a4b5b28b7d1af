"""Each page's modules as one file and its stylesheets as one: a handful of requests instead of fifty.

On HTTP/1.1 (six connections per origin) a page that names its 40 modules and 11 stylesheets up front
still waits a round trip for every sixth of them: on the field radio (300 ms round trips) that was
about two seconds of the dashboard's four before its event stream opened, with the link idle half
the time (BENCHMARKS.md, page load, third round). So, when a page is first asked for:

- its module scripts (`<script type="module" src="/static/js/...">`, in document order) become one
  bundle, made by esbuild (the well-kept bundler; a native binary from the npm registry that
  scripts/bootstrap.sh installs into .tools/, pinned below). Each of the page's modules is imported
  there with `import()`, in the order of its script tag, so each still runs on its own, in the same
  order as before, and one that throws stops only itself (as a failing <script> did); modules
  shared by several still run once. What is not under static/js (the vendored three.js of the 3D
  view) stays outside, loaded through the import map as before.
- its plain stylesheets (`<link rel="stylesheet" href="/static/...css">`) become one file, their
  texts in document order, which keeps the cascade; a sheet with @import, @charset or a relative
  url() stays on its own.

Both go into the content-addressed store (`js/bundle/<hash>.js`, `css/bundle/<hash>.css`, with their
brotli and gzip forms), served immutable like every hashed file; a changed module changes its page's
bundle and so its URL. Bundles are made once per set of entries and kept on disk: a later start,
or another worker, finds them by a key of esbuild's version, the entries and their modules' hashes.
Without esbuild (no npm where it was installed), or with ROVER_WEB_BUNDLE off, a page names its
modules up front as before (assets.py): slower on a slow link, the same page.
"""

from __future__ import annotations

import functools
import hashlib
import json
import logging
import os
import re
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

log = logging.getLogger(__name__)

ESBUILD_VERSION = "0.28.2"  # scripts/bootstrap.sh installs this one
# The bundle sits where a module of a feature does (js/<feature>/<name>.js), so an import kept
# outside it, written relative to such a module ('../../vendor/...'), resolves from it the same way.
JS_BUNDLES = "js/bundle"
CSS_BUNDLES = "css/bundle"
_ESBUILD_FLAGS = ("--bundle", "--format=esm", "--minify", "--charset=utf8", "--log-level=warning",
                  "--external:../../vendor/*", "--sourcemap=external", "--sourcefile=page.js")
FORMAT = 2  # how a bundle and its source map are made here: a change makes every bundle again
_UNBUNDLABLE_CSS = re.compile(r"""@import|@charset|url\(\s*(?!['"]?data:)""", re.IGNORECASE)


def find_esbuild(root: Path) -> str | None:
    """The native esbuild binary bootstrap installed (.tools/esbuild), else one on PATH."""
    for binary in sorted(root.glob(".tools/esbuild/node_modules/@esbuild/*/bin/esbuild")):
        if os.access(binary, os.X_OK):
            return str(binary)
    shim = root / ".tools" / "esbuild" / "node_modules" / ".bin" / "esbuild"
    if os.access(shim, os.X_OK):
        return str(shim)
    return shutil.which("esbuild")


def _digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:12]


class Bundles:
    """Makes and remembers each page's bundles. store(name, data) writes a file into the static store
    (hashed name, compressed forms) and makes the server serve it."""

    def __init__(self, static_dir: Path, build_dir: Path, hashed: dict[str, str],
                 store: Callable[[str, bytes], None], esbuild: str | None):
        self.static_dir, self.build_dir, self.hashed = static_dir, build_dir, hashed
        self._store, self.esbuild = store, esbuild
        self._made: dict[tuple[str, ...], str | None] = {}
        self._lock = threading.Lock()

    def scripts(self, entries: list[str]) -> str | None:
        """The bundle (a name in the store) of these modules of static/, or None: serve them as they are."""
        entries = tuple(e for e in entries if e.startswith("js/"))
        if not entries or self.esbuild is None:
            return None
        return self._once(("js",) + entries, lambda: self._make_scripts(entries))

    def styles(self, sheets: list[str]) -> tuple[str | None, list[str]]:
        """(one stylesheet for those that can be joined, or None; the ones joined, in order)."""
        joinable = [s for s in sheets if self._joinable(s)]
        if len(joinable) < 2:
            return None, []
        return self._once(("css",) + tuple(joinable), lambda: self._make_styles(joinable)), joinable

    @functools.cache  # noqa: B019 - one per app, static/ as it was at start
    def _joinable(self, sheet: str) -> bool:
        return sheet in self.hashed and not _UNBUNDLABLE_CSS.search(self._text(sheet))

    def _text(self, name: str) -> str:
        return (self.static_dir / name).read_text(encoding="utf-8", errors="replace")

    def _once(self, key: tuple[str, ...], make: Callable[[], str | None]) -> str | None:
        with self._lock:  # a page's first requests at once make it once
            if key not in self._made:
                try:
                    self._made[key] = make()
                except (OSError, subprocess.SubprocessError, ValueError) as exc:
                    log.warning("page bundle not made, its files are served one by one: %s", exc)
                    self._made[key] = None
            return self._made[key]

    def _key(self, kind: str, names: list[str] | tuple[str, ...]) -> str:
        # What the bundle is made of: the tool, the entries, and by content every module that could be
        # in it (all of static/js: a change anywhere there makes each page's bundle again at its next
        # first request, which gives the same URL when its content is the same).
        parts = [kind, str(FORMAT), ESBUILD_VERSION, *_ESBUILD_FLAGS, "|", *names, "|"]
        if kind == "js":
            parts += sorted(hashed for plain, hashed in self.hashed.items() if plain.startswith("js/"))
        else:
            parts += [self.hashed.get(name, name) for name in names]
        return hashlib.sha256("\n".join(parts).encode()).hexdigest()

    def _remembered(self, key: str) -> str | None:
        index = self.build_dir / "bundle-index" / key
        try:
            name = index.read_text().strip()
        except OSError:
            return None
        data = (self.build_dir / name).read_bytes() if (self.build_dir / name).is_file() else None
        if data is None:
            return None
        self._store(name, data)  # served from the store as it is (already compressed)
        for extra in (name + ".map",):
            if (self.build_dir / extra).is_file():
                self._store(extra, (self.build_dir / extra).read_bytes())
        return name

    def _remember(self, key: str, name: str) -> None:
        index = self.build_dir / "bundle-index"
        index.mkdir(parents=True, exist_ok=True)
        tmp = index / f".{key}.{os.getpid()}.tmp"
        tmp.write_text(name)
        os.replace(tmp, index / key)

    def _make_scripts(self, entries: tuple[str, ...]) -> str:
        key = self._key("js", entries)
        if (name := self._remembered(key)) is not None:
            return name
        js_dir = self.static_dir / "js"
        source = "".join(f'import("./{e[len("js/"):]}");\n' for e in entries)
        with tempfile.TemporaryDirectory(prefix="rover_web-bundle-") as tmp:
            out, meta = Path(tmp) / "page.js", Path(tmp) / "meta.json"
            run = subprocess.run([self.esbuild, *_ESBUILD_FLAGS, f"--outfile={out}", f"--metafile={meta}"],
                                 input=source.encode(), cwd=js_dir, capture_output=True, timeout=60)
            if run.returncode != 0:
                raise ValueError(f"esbuild: {run.stderr.decode(errors='replace').strip()[:500]}")
            code = out.read_bytes()
            source_map = self._sources_from_bundle(json.loads((Path(tmp) / "page.js.map").read_text()), Path(tmp))
            kept = [i["path"] for o in json.loads(meta.read_text())["outputs"].values() for i in o.get("imports", ())]
        # Whatever the bundle still imports must be a file of static/ as seen from its place.
        for spec in kept:
            target = os.path.normpath(os.path.join(JS_BUNDLES, spec)).replace(os.sep, "/")
            if not spec.startswith(".") or target not in self.hashed:
                raise ValueError(f"the bundle of {entries[0]}... imports {spec!r}, not a file of static/")
        if b"import.meta" in code:  # a module's own URL would be the bundle's: its relative URLs would miss
            raise ValueError(f"a module of {', '.join(entries)} uses import.meta")
        name = f"{JS_BUNDLES}/{_digest(code + source_map)}.js"  # the pair: each is stored once under its name
        self._store(name + ".map", source_map)
        self._store(name, code + f"//# sourceMappingURL={name.rsplit('/', 1)[1]}.map\n".encode())
        self._remember(key, name)
        log.info("page bundle %s: %d modules, %d bytes", name, len(entries), len(code))
        return name

    def _sources_from_bundle(self, source_map: dict, made_in: Path) -> bytes:
        # esbuild names the sources from where it wrote the bundle; name them from where it is served
        # ('../core/api.js' from js/bundle/), which also keeps the server's own paths out of the map.
        served_from = self.static_dir / JS_BUNDLES
        source_map["sources"] = [os.path.relpath(os.path.normpath(made_in / source), served_from).replace(os.sep, "/")
                                 for source in source_map["sources"]]
        return json.dumps(source_map, separators=(",", ":")).encode()

    def _make_styles(self, sheets: list[str]) -> str:
        key = self._key("css", sheets)
        if (name := self._remembered(key)) is not None:
            return name
        text = "".join(f"/* {sheet} */\n{self._text(sheet).rstrip()}\n" for sheet in sheets).encode()
        name = f"{CSS_BUNDLES}/{_digest(text)}.css"
        self._store(name, text)
        self._remember(key, name)
        return name
