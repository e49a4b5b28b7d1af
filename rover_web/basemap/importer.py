"""`flask tiles import`: a basemap another team made, as an MBTiles file or a GeoJSON file.

An MBTiles file (SQLite; MBTiles 1.3: `metadata(name, value)` and `tiles(zoom_level, tile_column,
tile_row, tile_data)`, rows in TMS order, which may be a view) is checked whole before anything is
written: every tile must be a PNG, JPEG or WebP image on the tile grid (vector tiles are refused:
the map draws raster tiles), so a bad file changes nothing. Its tiles are then copied into the
configured store, folder or MBTiles, with the store's own y flip. A GeoJSON file is checked as a
drawn basemap (features.py) and stored in the drawn-basemap folder.
"""

from __future__ import annotations

import math
import sqlite3
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from rover_web.web.api_messages import explain, text_of

from .features import NAME, BadFeatures, FeatureFolder, parse
from .tile_store import MAX_ZOOM, MBTiles, TileStoreError, image_format, valid_tile

VECTOR_FORMATS = {"pbf", "mvt"}
BATCH = 256


class ImportRefused(ValueError):
    """A file that cannot be imported; the message says which file, and why."""


@dataclass
class ImportResult:
    imported: int = 0
    kept: int = 0  # already in the store (replaced only with --force)


def _tile_lng(x: int, z: int) -> float:
    return x / (1 << z) * 360.0 - 180.0


def _tile_lat(y: int, z: int) -> float:
    return math.degrees(math.atan(math.sinh(math.pi * (1 - 2 * y / (1 << z)))))


def _open(path: Path) -> sqlite3.Connection:
    if not path.is_file():
        raise ImportRefused(explain("%(path)s: no such file", path=path))
    try:
        conn = sqlite3.connect(f"{path.resolve().as_uri()}?mode=ro", uri=True)
        names = {row[0] for row in conn.execute("SELECT name FROM sqlite_master WHERE type IN ('table', 'view')")}
    except sqlite3.DatabaseError as exc:
        raise ImportRefused(
            explain("%(path)s: not an MBTiles file (SQLite says: %(why)s)", path=path, why=text_of(exc))
        ) from None
    if "tiles" not in names:
        conn.close()
        raise ImportRefused(explain("%(path)s: not an MBTiles file: it has no 'tiles' table (MBTiles 1.3: "
                                    "metadata(name, value) and tiles(zoom_level, tile_column, tile_row, tile_data))",
                                    path=path))
    return conn


def _rows(conn: sqlite3.Connection, path: Path):
    try:
        yield from conn.execute("SELECT zoom_level, tile_column, tile_row, tile_data FROM tiles")
    except sqlite3.DatabaseError as exc:
        raise ImportRefused(explain("%(path)s: cannot read its tiles: %(why)s", path=path, why=text_of(exc))) from None


def import_mbtiles(path: Path, store, *, force: bool = False, attribution: str = "",
                   report: Callable[[str], None] = lambda line: None) -> ImportResult:
    """Copy every tile of the MBTiles file `path` into `store`; ImportRefused (nothing written) if any is bad."""
    if isinstance(store, MBTiles) and store.path.resolve() == path.resolve():
        raise ImportRefused(explain("%(path)s is the store itself", path=path))
    conn = _open(path)
    try:
        try:
            meta = {str(k): str(v) for k, v in conn.execute("SELECT name, value FROM metadata")}
        except sqlite3.DatabaseError:
            meta = {}
        if meta.get("format", "").lower() in VECTOR_FORMATS:
            raise ImportRefused(explain("%(path)s: holds vector tiles (format %(meta)s); the map draws raster "
                                        "tiles (PNG, JPEG, WebP): render them to raster first, or import the data "
                                        "as GeoJSON",
                                        path=path, meta=meta['format']))
        zooms: dict[int, list[int]] = {}  # z -> [x0, x1, y0, y1] in XYZ
        formats: set[str] = set()
        count = 0
        for z, x, row, data in _rows(conn, path):  # first pass: everything checked, nothing written
            where = f"{path}: tile zoom {z}, column {x}, row {row}"
            on_grid = all(isinstance(v, int) for v in (z, x, row)) and 0 <= z <= MAX_ZOOM \
                and valid_tile(z, x, (1 << z) - 1 - row)
            if not on_grid:
                raise ImportRefused(explain("%(where)s: not on the tile grid", where=where))
            fmt = image_format(bytes(data)) if isinstance(data, (bytes, memoryview)) else None
            if fmt is None:
                raise ImportRefused(explain("%(where)s: not a PNG, JPEG or WebP image", where=where))
            formats.add(fmt)
            y = (1 << z) - 1 - row
            box = zooms.setdefault(z, [x, x, y, y])
            box[:] = [min(box[0], x), max(box[1], x), min(box[2], y), max(box[3], y)]
            count += 1
        if not count:
            raise ImportRefused(explain("%(path)s: has no tiles", path=path))
        result = ImportResult()
        is_mbtiles = isinstance(store, MBTiles)
        if is_mbtiles:
            store.begin()
        try:
            for z, x, row, data in _rows(conn, path):
                y = (1 << z) - 1 - row
                if not force and store.has(z, x, y):
                    result.kept += 1
                    continue
                data = bytes(data)
                store.put(z, x, y, data, image_format(data))
                result.imported += 1
                if is_mbtiles and result.imported % BATCH == 0:
                    store.commit()
                    store.begin()
                if (result.imported + result.kept) % 1000 == 0:
                    report(f"{result.imported + result.kept}/{count} tiles")
        finally:
            if is_mbtiles:
                store.commit()
    finally:
        conn.close()
    top = max(zooms)
    x0, x1, y0, y1 = zooms[top]
    computed = [_tile_lng(x0, top), _tile_lat(y1 + 1, top), _tile_lng(x1 + 1, top), _tile_lat(y0, top)]
    bounds = _bounds(meta.get("bounds")) or computed
    store.update_metadata(bounds=bounds, minzoom=min(zooms), maxzoom=top,
                          attribution=attribution or meta.get("attribution", "")[:500],
                          source=f"the MBTiles file {path.name}", fmt=formats.pop() if len(formats) == 1 else None)
    return result


def _bounds(text) -> list[float] | None:
    try:
        west, south, east, north = (float(v) for v in str(text).split(","))
    except ValueError:
        return None
    ok = all(math.isfinite(v) for v in (west, south, east, north)) and -180 <= west < east <= 180 \
        and -90 <= south < north <= 90
    return [west, south, east, north] if ok else None


def import_geojson(path: Path, folder: FeatureFolder, *, name: str | None = None, attribution: str = "",
                   force: bool = False) -> Path:
    """Check `path` as a drawn basemap and store it in `folder`; ImportRefused if it is not one."""
    if not path.is_file():
        raise ImportRefused(explain("%(path)s: no such file", path=path))
    if name is None:
        name = "".join(c if c.isalnum() or c in "_-" else "-" for c in path.stem).strip("-_")[:64] or "imported"
    if not NAME.match(name):
        raise ImportRefused(explain("--name %(name)s: letters, digits, '_' and '-' only, at most 64, starting with "
                                    "a letter or digit",
                                    name=repr(name)))
    try:
        collection = parse(path.read_bytes(), str(path))
        if attribution:
            collection = {**collection, "attribution": attribution[:500]}
        return folder.write(name, collection, replace=force)
    except (BadFeatures, FileExistsError, OSError, TileStoreError) as exc:
        raise ImportRefused(text_of(exc)) from None
