"""Local raster tile stores for the offline basemap: a z/x/y folder or an MBTiles file. Pure Python.

Both use the XYZ ("slippy map") scheme on the outside: y = 0 is the northernmost row. MBTiles 1.3
stores rows in the TMS scheme (y = 0 in the south), so reads and writes flip y: row = 2^z - 1 - y.
"""

from __future__ import annotations

import json
import math
import os
import sqlite3
import tempfile
from pathlib import Path

MAX_ZOOM = 24
MAX_MERCATOR_LAT = 85.0511287798066  # Web Mercator's square world ends here
MEDIA_TYPES = {"png": "image/png", "jpg": "image/jpeg", "webp": "image/webp"}
METADATA_FILE = "metadata.json"


class TileStoreError(Exception):
    """A store that cannot be read or written; the message says which file and why."""


def image_format(data: bytes) -> str | None:
    """png, jpg or webp from the file's first bytes; None for anything else (an HTML error page)."""
    if data.startswith(b"\x89PNG\r\n\x1a\n"):
        return "png"
    if data.startswith(b"\xff\xd8\xff"):
        return "jpg"
    if len(data) >= 12 and data[:4] == b"RIFF" and data[8:12] == b"WEBP":
        return "webp"
    return None


def valid_tile(z: int, x: int, y: int) -> bool:
    return 0 <= z <= MAX_ZOOM and 0 <= x < (1 << z) and 0 <= y < (1 << z)


# --- tile math (XYZ, Web Mercator) ---

def tile_x(lng: float, z: int) -> int:
    n = 1 << z
    return min(n - 1, max(0, int(math.floor((lng + 180.0) / 360.0 * n))))


def tile_y(lat: float, z: int) -> int:
    n = 1 << z
    lat = max(-MAX_MERCATOR_LAT, min(MAX_MERCATOR_LAT, lat))
    y = (1.0 - math.asinh(math.tan(math.radians(lat))) / math.pi) / 2.0 * n
    return min(n - 1, max(0, int(math.floor(y))))


def tile_ranges(bbox: tuple[float, float, float, float], zoom_min: int, zoom_max: int):
    """[(z, x0, x1, y0, y1)] inclusive ranges covering bbox (W, S, E, N) at every zoom."""
    west, south, east, north = bbox
    return [(z, tile_x(west, z), tile_x(east, z), tile_y(north, z), tile_y(south, z))
            for z in range(zoom_min, zoom_max + 1)]


def tile_count(bbox, zoom_min: int, zoom_max: int) -> int:
    return sum((x1 - x0 + 1) * (y1 - y0 + 1) for _, x0, x1, y0, y1 in tile_ranges(bbox, zoom_min, zoom_max))


def _merge_bounds(a, b):
    if not a:
        return list(b) if b else None
    if not b:
        return list(a)
    return [min(a[0], b[0]), min(a[1], b[1]), max(a[2], b[2]), max(a[3], b[3])]


def _clean_bounds(value) -> list[float] | None:
    """[W, S, E, N] if value is a sane bounds list or "W,S,E,N" string, else None."""
    if isinstance(value, str):
        value = value.split(",")
    try:
        west, south, east, north = (float(v) for v in value)
    except (TypeError, ValueError):
        return None
    if not all(math.isfinite(v) for v in (west, south, east, north)):
        return None
    if not (-180 <= west < east <= 180 and -90 <= south < north <= 90):
        return None
    return [west, south, east, north]


def _clean_zoom(value) -> int | None:
    try:
        zoom = int(value)
    except (TypeError, ValueError):
        return None
    return zoom if 0 <= zoom <= MAX_ZOOM else None


# --- stores ---

class FolderTiles:
    """`<root>/<z>/<x>/<y>.<png|jpg|webp>` plus an optional metadata.json written by `tiles fetch`."""

    kind = "folder"

    def __init__(self, root: str | os.PathLike):
        self.root = Path(root)

    def exists(self) -> bool:
        return self.root.is_dir() and any(p.name.isdigit() and p.is_dir() for p in self.root.iterdir())

    def _path(self, z: int, x: int, y: int, fmt: str) -> Path:
        return self.root / str(z) / str(x) / f"{y}.{fmt}"

    def get(self, z: int, x: int, y: int) -> tuple[bytes, str] | None:
        for fmt in MEDIA_TYPES:
            try:
                return self._path(z, x, y, fmt).read_bytes(), fmt
            except (FileNotFoundError, NotADirectoryError):
                continue
        return None

    def has(self, z: int, x: int, y: int) -> bool:
        return any(self._path(z, x, y, fmt).is_file() for fmt in MEDIA_TYPES)

    def put(self, z: int, x: int, y: int, data: bytes, fmt: str) -> None:
        """Write atomically (temporary file, then rename): a killed fetch never leaves half a tile."""
        path = self._path(z, x, y, fmt)
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{y}.", suffix=".part")
        try:
            with os.fdopen(fd, "wb") as fh:
                fh.write(data)
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise

    def metadata(self) -> dict:
        meta: dict = {}
        try:
            meta = json.loads((self.root / METADATA_FILE).read_text())
        except (OSError, ValueError):
            pass
        if not isinstance(meta, dict):
            meta = {}
        zooms = sorted(int(p.name) for p in self.root.iterdir() if p.name.isdigit() and p.is_dir()) \
            if self.root.is_dir() else []
        return {
            "minzoom": _clean_zoom(meta.get("minzoom")) if "minzoom" in meta else (zooms[0] if zooms else None),
            "maxzoom": _clean_zoom(meta.get("maxzoom")) if "maxzoom" in meta else (zooms[-1] if zooms else None),
            "bounds": _clean_bounds(meta.get("bounds")),
            "attribution": str(meta.get("attribution") or "")[:500],
            "name": str(meta.get("name") or self.root.name)[:200],
        }

    def update_metadata(self, *, bounds, minzoom: int, maxzoom: int, attribution: str, source: str,
                        fmt: str | None = None) -> None:
        old = {}
        try:
            old = json.loads((self.root / METADATA_FILE).read_text())
        except (OSError, ValueError):
            pass
        old = old if isinstance(old, dict) else {}
        old_min, old_max = _clean_zoom(old.get("minzoom")), _clean_zoom(old.get("maxzoom"))
        meta = {
            "name": old.get("name") or self.root.name,
            "bounds": _merge_bounds(_clean_bounds(old.get("bounds")), bounds),
            "minzoom": minzoom if old_min is None else min(minzoom, old_min),
            "maxzoom": maxzoom if old_max is None else max(maxzoom, old_max),
            "attribution": attribution or old.get("attribution") or "",
            "format": fmt or old.get("format") or "png",
            "source": source,
        }
        self.root.mkdir(parents=True, exist_ok=True)
        tmp = self.root / (METADATA_FILE + ".part")
        tmp.write_text(json.dumps(meta, indent=2) + "\n")
        os.replace(tmp, self.root / METADATA_FILE)

    def close(self) -> None:
        pass


MBTILES_SCHEMA = """
CREATE TABLE IF NOT EXISTS metadata (name TEXT, value TEXT);
CREATE UNIQUE INDEX IF NOT EXISTS metadata_name ON metadata (name);
CREATE TABLE IF NOT EXISTS tiles (zoom_level INTEGER, tile_column INTEGER, tile_row INTEGER, tile_data BLOB);
CREATE UNIQUE INDEX IF NOT EXISTS tile_index ON tiles (zoom_level, tile_column, tile_row)
"""


class MBTiles:
    """An MBTiles 1.3 file (SQLite; rows in TMS order). Read-only unless opened with writable=True."""

    kind = "mbtiles"

    def __init__(self, path: str | os.PathLike, writable: bool = False):
        self.path = Path(path)
        self.writable = writable
        self._conn: sqlite3.Connection | None = None

    def _connect(self) -> sqlite3.Connection:
        if self._conn is None:
            try:
                if self.writable:
                    self.path.parent.mkdir(parents=True, exist_ok=True)
                    conn = sqlite3.connect(self.path, isolation_level=None)
                    conn.executescript(MBTILES_SCHEMA)
                else:
                    conn = sqlite3.connect(f"{self.path.resolve().as_uri()}?mode=ro", uri=True,
                                           isolation_level=None, check_same_thread=False)
            except sqlite3.Error as exc:
                raise TileStoreError(f"{self.path}: cannot open as MBTiles: {exc}") from None
            self._conn = conn
        return self._conn

    def exists(self) -> bool:
        if not self.path.is_file():
            return False
        try:
            return self._connect().execute("SELECT 1 FROM tiles LIMIT 1").fetchone() is not None
        except (sqlite3.Error, TileStoreError):
            return False

    def get(self, z: int, x: int, y: int) -> tuple[bytes, str] | None:
        try:
            row = self._connect().execute(
                "SELECT tile_data FROM tiles WHERE zoom_level = ? AND tile_column = ? AND tile_row = ?",
                (z, x, (1 << z) - 1 - y)).fetchone()
        except sqlite3.Error as exc:
            raise TileStoreError(f"{self.path}: {exc}") from None
        if row is None or row[0] is None:
            return None
        data = bytes(row[0])
        return data, image_format(data) or "png"

    def has(self, z: int, x: int, y: int) -> bool:
        return self._connect().execute(
            "SELECT 1 FROM tiles WHERE zoom_level = ? AND tile_column = ? AND tile_row = ?",
            (z, x, (1 << z) - 1 - y)).fetchone() is not None

    def put(self, z: int, x: int, y: int, data: bytes, fmt: str) -> None:
        conn = self._connect()
        conn.execute("INSERT OR REPLACE INTO tiles (zoom_level, tile_column, tile_row, tile_data) VALUES (?, ?, ?, ?)",
                     (z, x, (1 << z) - 1 - y, sqlite3.Binary(data)))

    def _meta(self) -> dict[str, str]:
        try:
            return {str(k): str(v) for k, v in self._connect().execute("SELECT name, value FROM metadata")}
        except sqlite3.Error:
            return {}

    def metadata(self) -> dict:
        meta = self._meta()
        minzoom, maxzoom = _clean_zoom(meta.get("minzoom")), _clean_zoom(meta.get("maxzoom"))
        if minzoom is None or maxzoom is None:
            try:
                low, high = self._connect().execute("SELECT min(zoom_level), max(zoom_level) FROM tiles").fetchone()
            except sqlite3.Error:
                low = high = None
            minzoom = _clean_zoom(low) if minzoom is None else minzoom
            maxzoom = _clean_zoom(high) if maxzoom is None else maxzoom
        return {"minzoom": minzoom, "maxzoom": maxzoom, "bounds": _clean_bounds(meta.get("bounds")),
                "attribution": meta.get("attribution", "")[:500], "name": meta.get("name", self.path.stem)[:200]}

    def update_metadata(self, *, bounds, minzoom: int, maxzoom: int, attribution: str, source: str,
                        fmt: str | None = None) -> None:
        old = self._meta()
        old_min, old_max = _clean_zoom(old.get("minzoom")), _clean_zoom(old.get("maxzoom"))
        merged = _merge_bounds(_clean_bounds(old.get("bounds")), bounds)
        values = {
            "name": old.get("name") or self.path.stem,
            "format": fmt or old.get("format") or "png",
            "type": "baselayer",
            "version": "1.3",
            "bounds": ",".join(f"{v:.7f}" for v in merged) if merged else "",
            "minzoom": str(minzoom if old_min is None else min(minzoom, old_min)),
            "maxzoom": str(maxzoom if old_max is None else max(maxzoom, old_max)),
            "attribution": attribution or old.get("attribution", ""),
            "description": f"tiles from {source}",
        }
        conn = self._connect()
        with_tx(conn, lambda: conn.executemany("INSERT OR REPLACE INTO metadata (name, value) VALUES (?, ?)",
                                               values.items()))

    def begin(self) -> None:
        self._connect().execute("BEGIN IMMEDIATE")

    def commit(self) -> None:
        self._connect().execute("COMMIT")

    def close(self) -> None:
        if self._conn is not None:
            self._conn.close()
            self._conn = None


def with_tx(conn: sqlite3.Connection, fn) -> None:
    conn.execute("BEGIN IMMEDIATE")
    try:
        fn()
    except BaseException:
        conn.execute("ROLLBACK")
        raise
    conn.execute("COMMIT")


def open_tile_store(path: str | os.PathLike, writable: bool = False):
    """FolderTiles or MBTiles by the path's suffix (.mbtiles means a file)."""
    path = Path(path)
    if path.suffix.lower() == ".mbtiles":
        return MBTiles(path, writable=writable)
    return FolderTiles(path)
