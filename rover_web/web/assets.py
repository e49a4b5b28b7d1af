"""Static files by content: hashed URLs cached for a year, pre-compressed, each page's modules named up front.

On a radio link every request is a round trip of 300 ms or more and every byte counts, so:

- At start, each file under static/ gets a content hash; a copy named `<name>.<hash12>.<ext>` and its
  brotli and gzip forms go into a content-addressed store (ROVER_WEB_STATIC_BUILD_DIR). A file is
  compressed once, the first time its content is seen; later starts only hash (a few ms). No build
  step: a developer edits static/ and restarts, as before.
- WhiteNoise serves that store under /static/: the encoding the browser accepts, `Vary:
  Accept-Encoding`, `Cache-Control: public, max-age=31536000, immutable`. An un-hashed URL is not in
  the store and falls through to Flask's own static view, `no-cache` and uncompressed, as before.
- `url_for('static', filename=...)` gives the hashed URL, so no template names a hash.
- Every HTML page gets, in its head, an import map from each module's plain URL to its hashed one
  (relative imports inside modules stay as they are written and still land on immutable URLs), and
  a `<link rel="modulepreload">` for every module its scripts import statically, found by reading
  the imports once at start: the browser fetches the whole graph at once instead of one import level
  per round trip. Modules reached only by `import()` are mapped, not preloaded (they come later, on
  purpose). The import map is an inline script: it carries a per-response nonce, which that response's
  Content-Security-Policy allows, and nothing else inline is.
"""

from __future__ import annotations

import hashlib
import html
import json
import logging
import os
import re
import secrets
import time
from dataclasses import dataclass, field
from pathlib import Path

from flask import Flask, request
from flask_compress import Compress
from whitenoise import WhiteNoise
from whitenoise.compress import Compressor

from .bundles import Bundles, find_esbuild
from .http import CONTENT_SECURITY_POLICY

log = logging.getLogger(__name__)

HASH_CHARS = 12
IMMUTABLE = "public, max-age=31536000, immutable"
# Import statements and dynamic imports with a literal relative specifier; a `//` comment line is skipped.
_IMPORT = re.compile(r"""^[ \t]*(?:import|export)\b[^'";]*?\bfrom\s*(['"])(\.{1,2}/[^'"]+)\1"""
                     r"""|^[ \t]*import\s*(['"])(\.{1,2}/[^'"]+)\3""", re.MULTILINE)
_DYNAMIC = re.compile(r"""\bimport\(\s*(['"])(\.{1,2}/[^'"]+)\1\s*\)""")
_MODULE_SCRIPT = re.compile(r"""<script type="module" src="([^"]+)"></script>""")
_STYLESHEET = re.compile(r"""<link rel="stylesheet" href="([^"]+\.css)">""")
# Compress what compresses; images, fonts and archives are compressed already.
_COMPRESSIBLE = re.compile(r"\.(js|mjs|css|json|geojson|svg|html|txt|map|xml)\Z")


@dataclass
class Manifest:
    """static/ as the server sees it at start: hashed names and the modules' import graph."""
    hashed: dict[str, str] = field(default_factory=dict)        # 'js/core/api.js' -> 'js/core/api.<h>.js'
    plain_of: dict[str, str] = field(default_factory=dict)      # the reverse
    imports: dict[str, tuple[str, ...]] = field(default_factory=dict)   # static imports, plain names
    dynamic: dict[str, tuple[str, ...]] = field(default_factory=dict)   # import('...') with a literal

    def closure(self, entries: list[str]) -> tuple[list[str], list[str]]:
        """(modules loaded with the entries, modules only imported later with import()), in order."""
        eager = _reach(entries, lambda name: self.imports.get(name, ()))
        starts = [dep for name in eager for dep in self.dynamic.get(name, ())]
        later = _reach(starts, lambda name: self.imports.get(name, ()) + self.dynamic.get(name, ()))
        loaded = set(eager)
        return eager, [name for name in later if name not in loaded]


def _reach(starts, edges) -> list[str]:
    order, seen, todo = [], set(), list(starts)
    while todo:
        name = todo.pop(0)
        if name not in seen:
            seen.add(name)
            order.append(name)
            todo.extend(edges(name))
    return order


def hashed_name(name: str, digest: str) -> str:
    stem, dot, ext = name.rpartition(".")
    return f"{stem}.{digest}.{ext}" if dot and "/" not in ext else f"{name}.{digest}"


def _resolve(importer: str, specifier: str) -> str:
    return os.path.normpath(os.path.join(os.path.dirname(importer), specifier)).replace(os.sep, "/")


def _write_atomically(path: Path, data: bytes) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def _sources(static_dir: Path, generated: dict[str, bytes]):
    for path in sorted(static_dir.rglob("*")):
        if path.is_file() and not any(part.startswith(".") for part in path.relative_to(static_dir).parts):
            yield path.relative_to(static_dir).as_posix(), path.read_bytes()
    yield from sorted(generated.items())


def build(static_dir: Path, build_dir: Path, generated: dict[str, bytes] | None = None) -> Manifest:
    """Hash every file of static_dir; copy and compress into build_dir what it does not hold yet.

    The store is content-addressed, so a copy is never stale and two servers (or an old page still
    open after an upgrade) share it safely. The plain copy is written last: its presence says its
    .br and .gz are complete. `generated` are files made at start ({name: content}, such as the
    browser's translation catalogues, rover_web/i18n), served exactly as if they were in static_dir.
    """
    manifest = Manifest()
    compressor = Compressor(quiet=True)
    made = 0
    for name, data in _sources(static_dir, generated or {}):
        digest = hashlib.sha256(data).hexdigest()[:HASH_CHARS]
        hashed = hashed_name(name, digest)
        manifest.hashed[name] = hashed
        manifest.plain_of[hashed] = name
        if name.endswith(".js") and name.startswith("js/"):
            text = data.decode("utf-8", "replace")
            manifest.imports[name] = tuple(_resolve(name, m.group(2) or m.group(4)) for m in _IMPORT.finditer(text))
            manifest.dynamic[name] = tuple(_resolve(name, m.group(2)) for m in _DYNAMIC.finditer(text))
        made += store(build_dir, hashed, data, compressor)
    if made:
        log.info("static files: %d new hashed copies in %s", made, build_dir)
    return manifest


def store(build_dir: Path, hashed: str, data: bytes, compressor: Compressor | None = None) -> bool:
    """Put a file under its hashed name into the store with its brotli and gzip forms; False: it was there."""
    target = build_dir / hashed
    if target.exists():
        return False
    compressor = compressor or Compressor(quiet=True)
    target.parent.mkdir(parents=True, exist_ok=True)
    if _COMPRESSIBLE.search(hashed):
        for suffix, compress in ((".br", compressor.compress_brotli), (".gz", compressor.compress_gzip)):
            packed = compress(data)
            if len(packed) < len(data) * 0.95:  # as WhiteNoise's own rule: not worth a header otherwise
                _write_atomically(target.with_name(target.name + suffix), packed)
    _write_atomically(target, data)
    return True


def _static_headers(headers, path, url) -> None:
    # Every name in the store carries its content's hash: it never changes under its URL.
    headers["Cache-Control"] = IMMUTABLE
    headers["X-Content-Type-Options"] = "nosniff"


def _page(manifest: Manifest, bundles: Bundles | None, body: str, static_root: str) -> tuple[str, str | None]:
    """The page with its stylesheets joined and its modules bundled (or named up front), and the nonce
    of its import map (None: the page has no module script)."""
    prefix = static_root + "/"

    def plain(url: str) -> str | None:
        url = html.unescape(url)
        return manifest.plain_of.get(url[len(prefix):]) if url.startswith(prefix) else None

    if bundles is not None:
        sheets = [(m.group(0), plain(m.group(1))) for m in _STYLESHEET.finditer(body)]
        joined_name, joined = bundles.styles(list(dict.fromkeys(name for _, name in sheets if name)))
        if joined_name:
            link = f'<link rel="stylesheet" href="{html.escape(prefix + joined_name)}">'
            for tag, name in sheets:  # the first joined sheet's place takes them all, in their order
                if name in joined:
                    body, link = body.replace(tag, link, 1), ""
    scripts = [(m.group(0), plain(m.group(1))) for m in _MODULE_SCRIPT.finditer(body)]
    entries = list(dict.fromkeys(name for _, name in scripts if name))
    if not entries:
        return body, None
    eager, later = manifest.closure(entries)
    mapped = {prefix + name: prefix + manifest.hashed[name] for name in eager + later if name in manifest.hashed}
    nonce = secrets.token_urlsafe(16)
    imports = json.dumps({"imports": mapped}, separators=(",", ":")).replace("</", "<\\/")
    lines = [f'<script type="importmap" nonce="{nonce}">{imports}</script>']
    bundle = bundles.scripts(entries) if bundles is not None else None
    if bundle:
        for tag, name in scripts:
            if name is not None and name.startswith("js/"):
                body = body.replace(tag, "", 1)
        # In the head: its download starts as the page's first bytes arrive; a module runs after parsing.
        lines.append(f'<script type="module" src="{html.escape(prefix + bundle)}"></script>')
        preload = [name for name in eager if not name.startswith("js/")]  # what the bundle keeps outside
    else:
        preload = [name for name in eager if name not in entries]
    lines += [f'<link rel="modulepreload" href="{html.escape(prefix + manifest.hashed[name])}">'
              for name in preload if name in manifest.hashed]
    at = body.find("</head>")
    return body[:at] + "\n".join(lines) + "\n" + body[at:], nonce


def build_dir_for(static_dir: Path, setting: str | None) -> Path:
    return Path(setting) if setting else static_dir.parent / "build" / "static"


def init_app(app: Flask) -> None:
    static_dir = Path(app.static_folder)
    build_dir = build_dir_for(static_dir, app.config.get("ROVER_WEB_STATIC_BUILD_DIR"))
    try:
        build_dir.mkdir(parents=True, exist_ok=True)
        # Files made at start by a feature set up before this (the i18n catalogues), beside static/'s.
        manifest = build(static_dir, build_dir, app.extensions.get("rover_web.generated_static"))
    except OSError as exc:
        # A read-only install still serves every page, only without long caching or compression.
        log.warning("static files are served un-hashed and uncompressed: %s is not writable (%s); "
                    "set ROVER_WEB_STATIC_BUILD_DIR to a writable directory", build_dir, exc)
        return
    app.extensions["rover_web.assets"] = manifest

    wn = WhiteNoise(app.wsgi_app, allow_all_origins=False, add_headers_function=_static_headers,
                    immutable_file_test=lambda path, url: True)
    # Only the current files: the store may also hold earlier versions, which nobody is sent to.
    static_url = app.static_url_path.rstrip("/")
    for hashed in manifest.hashed.values():
        wn.add_file_to_dictionary(f"{static_url}/{hashed}", str(build_dir / hashed), stat_cache=None)
    app.wsgi_app = wn

    def serve(name: str, data: bytes) -> None:  # a page's bundle, made at its first request
        store(build_dir, name, data)
        wn.add_file_to_dictionary(f"{static_url}/{name}", str(build_dir / name), stat_cache=None)

    bundles = None
    if app.config.get("ROVER_WEB_BUNDLE", True):
        esbuild = find_esbuild(Path(__file__).resolve().parents[2])
        if esbuild is None:
            log.warning("esbuild not found (scripts/bootstrap.sh installs it into .tools/): each page's modules "
                        "are served one by one, named up front; slower on a slow link (docs/page_load.md)")
        bundles = Bundles(static_dir, build_dir, manifest.hashed, serve, esbuild)

    @app.url_defaults
    def _hashed_static(endpoint, values):
        if endpoint == "static" and "filename" in values:
            values["filename"] = manifest.hashed.get(values["filename"], values["filename"])

    # Pages and JSON above a small size are compressed as they go out (Flask-Compress). Streams are
    # not: an event stream is written by the Broadcaster, and a streamed body stays as it is.
    app.config.setdefault("COMPRESS_ALGORITHM", ["br", "gzip"])
    # What is text; never text/event-stream (the event stream) nor multipart (the camera's MJPEG).
    app.config.setdefault("COMPRESS_MIMETYPES", ["text/html", "text/css", "text/plain", "text/javascript",
                                                 "application/javascript", "application/json",
                                                 "application/geo+json", "application/xml", "image/svg+xml"])
    app.config.setdefault("COMPRESS_MIN_SIZE", 1024)
    app.config.setdefault("COMPRESS_STREAMS", False)
    app.config.setdefault("COMPRESS_BR_LEVEL", 4)
    Compress(app)  # its after_request runs after the one below (Flask runs them last-registered first)

    @app.after_request
    def _name_modules(response):
        if (response.mimetype != "text/html" or response.is_streamed or response.direct_passthrough
                or response.status_code >= 300 and response.status_code != 404):
            return response
        body = response.get_data(as_text=True)
        if body.find("</head>") < 0:
            return response
        body, nonce = _page(manifest, bundles, body, request.script_root + static_url)
        response.set_data(body)
        if nonce is None:
            return response
        response.headers["Content-Security-Policy"] = CONTENT_SECURITY_POLICY.replace(
            "script-src 'self'", f"script-src 'self' 'nonce-{nonce}'")
        return response


if __name__ == "__main__":
    # `python -m rover_web.web.assets`: fill the store before the first start (scripts/demo.sh and
    # scripts/test.sh do), so that start, or two test workers at once, do not compress it themselves.
    started = time.monotonic()
    static = Path(__file__).resolve().parents[2] / "static"
    # Not named `store`: this block runs at module level, and build() calls the function of that name.
    store_dir = build_dir_for(static, os.environ.get("ROVER_WEB_STATIC_BUILD_DIR"))
    store_dir.mkdir(parents=True, exist_ok=True)
    built = build(static, store_dir)
    print(f"static files: {len(built.hashed)} hashed and compressed in {store_dir} "
          f"({time.monotonic() - started:.1f} s)")
