"""The offline basemap: tiles served by the app itself (GET /tiles/z/x/y) and `flask tiles fetch`.

By default the map fetches nothing from the internet. An operator fills a local store once, while
online, with `flask --app rover_web tiles fetch --bbox W,S,E,N --zoom A-B --url TEMPLATE`, and the
map then shows those tiles in the field. The store is the folder or .mbtiles file named by
ROVER_WEB_MAP_TILES (relative paths from the repository root, like ROVER_WEB_MAPS_FILE; default
map_files/tiles); the page asks only this app for tiles.
"""

from __future__ import annotations

import math
import sys
import time
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import click
from flask import Blueprint, Flask, Response, current_app
from flask.cli import AppGroup

from rover_web.config import ROOT
from .tile_store import (
    MAX_ZOOM,
    MEDIA_TYPES,
    MBTiles,
    TileStoreError,
    image_format,
    open_tile_store,
    tile_count,
    tile_ranges,
    valid_tile,
)

TILE_URL = "/tiles/{z}/{x}/{y}"
DEFAULT_MAX_TILES = 5000
USER_AGENT = "rover_web-tiles-fetch/0.1 (offline basemap for a robot GUI)"

bp = Blueprint("tiles", __name__)


def store_path(config) -> Path | None:
    value = config.get("ROVER_WEB_MAP_TILES")
    if not value:
        return None
    path = Path(value).expanduser()
    return path if path.is_absolute() else ROOT / path


def installed_store(config):
    """The configured store if it exists and holds tiles, else None (the map runs without basemap)."""
    path = store_path(config)
    if path is None:
        return None
    store = open_tile_store(path)
    if store.exists():
        return store
    store.close()
    return None


def basemap(config) -> dict | None:
    """What the page's raster source needs, or None when no basemap is installed."""
    store = installed_store(config)
    if store is None:
        return None
    try:
        meta = store.metadata()
    except TileStoreError:
        return None
    finally:
        store.close()
    source = {"tiles": [TILE_URL], "tileSize": 256, "attribution": meta["attribution"], "name": meta["name"]}
    if meta["minzoom"] is not None:
        source["minzoom"] = meta["minzoom"]
    if meta["maxzoom"] is not None:
        source["maxzoom"] = meta["maxzoom"]
    if meta["bounds"]:
        source["bounds"] = meta["bounds"]
    return source


@bp.get("/tiles/<int:z>/<int:x>/<int:y>")
def tile(z: int, x: int, y: int):
    store = installed_store(current_app.config) if valid_tile(z, x, y) else None
    if store is None:
        return Response(status=404)
    try:
        found = store.get(z, x, y)
    except TileStoreError as exc:
        current_app.logger.warning("tile %s/%s/%s: %s", z, x, y, exc)
        found = None
    finally:
        store.close()
    if found is None:
        return Response(status=404)
    data, fmt = found
    response = Response(data, mimetype=MEDIA_TYPES.get(fmt, "application/octet-stream"))
    response.headers["Cache-Control"] = "public, max-age=3600"
    return response


# --- filling the store ---

class TooManyTiles(ValueError):
    def __init__(self, count: int, limit: int):
        super().__init__(f"that area and zoom range is {count:,} tiles; the limit is {limit:,}. "
                         f"Choose a smaller --bbox or fewer --zoom levels, or raise --max-tiles if you "
                         f"really mean it (and the tile server's usage policy allows it).")
        self.count, self.limit = count, limit


def parse_bbox(text: str) -> tuple[float, float, float, float]:
    parts = text.split(",")
    try:
        west, south, east, north = (float(p) for p in parts)
    except ValueError:
        raise click.BadParameter(f"expected W,S,E,N in degrees, e.g. -82.47,27.36,-82.43,27.39; got {text!r}") from None
    if not all(math.isfinite(v) for v in (west, south, east, north)):
        raise click.BadParameter("coordinates must be finite numbers")
    if not (-180 <= west < east <= 180):
        raise click.BadParameter(f"need -180 <= W < E <= 180 (an area across the antimeridian: fetch it in two parts); got W={west}, E={east}")
    if not (-90 <= south < north <= 90):
        raise click.BadParameter(f"need -90 <= S < N <= 90; got S={south}, N={north}")
    return west, south, east, north


def parse_zoom(text: str) -> tuple[int, int]:
    low, sep, high = text.partition("-")
    try:
        zoom_min = int(low)
        zoom_max = int(high) if sep else zoom_min
    except ValueError:
        raise click.BadParameter(f"expected a zoom level or range such as 12-17; got {text!r}") from None
    if not 0 <= zoom_min <= zoom_max <= MAX_ZOOM:
        raise click.BadParameter(f"need 0 <= A <= B <= {MAX_ZOOM}; got {text!r}")
    return zoom_min, zoom_max


def check_url_template(url: str) -> str:
    if not url.startswith(("http://", "https://")):
        raise click.BadParameter("the tile URL must start with http:// or https://")
    missing = [key for key in ("{z}", "{x}", "{y}") if key not in url]
    if missing:
        raise click.BadParameter(f"the tile URL template needs {', '.join(missing)}, e.g. http://host/{{z}}/{{x}}/{{y}}.png")
    return url


@dataclass
class FetchResult:
    planned: int = 0
    fetched: int = 0
    kept: int = 0      # already in the store (skipped unless --force)
    missing: int = 0   # the server answered 404: it has no such tile
    failed: int = 0    # errors, non-image answers


def download(url: str, timeout_s: float, retries: int) -> bytes | None:
    """The tile's bytes, None on 404; raises OSError/ValueError after retries for anything else."""
    request = urllib.request.Request(url, headers={"User-Agent": USER_AGENT})
    for attempt in range(retries + 1):
        try:
            with urllib.request.urlopen(request, timeout=timeout_s) as response:
                data = response.read()
            if image_format(data) is None:
                raise ValueError(f"{url}: the answer is not a PNG, JPEG or WebP image")
            return data
        except urllib.error.HTTPError as exc:
            if exc.code in (404, 204):
                return None
            if attempt == retries or exc.code not in (429, 500, 502, 503, 504):
                raise
        except (urllib.error.URLError, TimeoutError, ConnectionError):
            if attempt == retries:
                raise
        time.sleep(0.5 * (attempt + 1))
    return None  # pragma: no cover


def fetch_tiles(store, url_template: str, bbox, zoom_min: int, zoom_max: int, *, max_tiles: int,
                force: bool = False, attribution: str = "", delay_s: float = 0.0, timeout_s: float = 10.0,
                retries: int = 2, report: Callable[[str], None] = lambda line: None) -> FetchResult:
    planned = tile_count(bbox, zoom_min, zoom_max)
    if planned > max_tiles:
        raise TooManyTiles(planned, max_tiles)
    result = FetchResult(planned=planned)
    formats: set[str] = set()
    batch = 0
    is_mbtiles = isinstance(store, MBTiles)
    if is_mbtiles:
        store.begin()
    try:
        for z, x0, x1, y0, y1 in tile_ranges(bbox, zoom_min, zoom_max):
            for x in range(x0, x1 + 1):
                for y in range(y0, y1 + 1):
                    if not force and store.has(z, x, y):
                        result.kept += 1
                        continue
                    url = url_template.replace("{z}", str(z)).replace("{x}", str(x)).replace("{y}", str(y))
                    try:
                        data = download(url, timeout_s, retries)
                    except (OSError, ValueError) as exc:
                        result.failed += 1
                        report(f"failed: {url}: {exc}")
                        continue
                    if data is None:
                        result.missing += 1
                        continue
                    fmt = image_format(data)
                    formats.add(fmt)
                    store.put(z, x, y, data, fmt)
                    result.fetched += 1
                    batch += 1
                    if is_mbtiles and batch >= 64:  # commit in batches: an interrupted fetch keeps its work
                        store.commit()
                        store.begin()
                        batch = 0
                    done = result.fetched + result.kept + result.missing + result.failed
                    if done % 100 == 0:
                        report(f"{done}/{planned} tiles")
                    if delay_s:
                        time.sleep(delay_s)
        if is_mbtiles:
            store.commit()
            is_mbtiles = False
    finally:
        if is_mbtiles:  # an exception (Ctrl-C) left a batch open: keep what was fetched
            store.commit()
    if result.fetched or result.kept:
        store.update_metadata(bounds=list(bbox), minzoom=zoom_min, maxzoom=zoom_max, attribution=attribution,
                              source=url_template, fmt=sorted(formats)[0] if len(formats) == 1 else None)
    return result


def init_cli(app: Flask) -> None:
    """`flask --app rover_web tiles ...`: registered without starting a ROS node."""
    tiles = AppGroup("tiles", help="Offline basemap tiles for the waypoints map.")

    @tiles.command("fetch")
    @click.option("--bbox", required=True, help="area as W,S,E,N in degrees, e.g. -82.47,27.36,-82.43,27.39")
    @click.option("--zoom", required=True, help="zoom levels, a range A-B or one level, e.g. 12-17")
    @click.option("--url", "url_template", required=True,
                  help="tile server URL template with {z}, {x}, {y}, e.g. http://tiles.local/{z}/{x}/{y}.png")
    @click.option("--out", type=click.Path(), default=None,
                  help="tile folder or .mbtiles file (default: ROVER_WEB_MAP_TILES, map_files/tiles)")
    @click.option("--max-tiles", type=click.IntRange(1), default=DEFAULT_MAX_TILES, show_default=True,
                  help="refuse to start if the area needs more tiles than this")
    @click.option("--attribution", default="", help="credit line shown on the map, e.g. '© OpenStreetMap contributors'")
    @click.option("--force", is_flag=True, help="download tiles that are already in the store again")
    @click.option("--delay-s", type=click.FloatRange(0, 60), default=0.0, show_default=True,
                  help="pause between downloads, to respect a public server's usage policy")
    def fetch(bbox, zoom, url_template, out, max_tiles, attribution, force, delay_s):
        """Download the tiles covering an area into the local store, for use offline."""
        box = parse_bbox(bbox)
        zoom_min, zoom_max = parse_zoom(zoom)
        url_template = check_url_template(url_template)
        target = Path(out) if out else store_path(current_app.config)
        if target is None:
            raise click.UsageError("ROVER_WEB_MAP_TILES is unset: name a store with --out")
        planned = tile_count(box, zoom_min, zoom_max)
        if planned > max_tiles:
            raise click.ClickException(str(TooManyTiles(planned, max_tiles)))
        store = open_tile_store(target, writable=True)
        click.echo(f"fetching {planned} tiles (zoom {zoom_min}-{zoom_max}) into {target}")
        try:
            result = fetch_tiles(store, url_template, box, zoom_min, zoom_max, max_tiles=max_tiles, force=force,
                                 attribution=attribution, delay_s=delay_s,
                                 report=lambda line: click.echo(line, err=True))
        except TileStoreError as exc:
            raise click.ClickException(str(exc)) from None
        finally:
            store.close()
        click.echo(f"done: {result.fetched} fetched, {result.kept} already there, {result.missing} not on the "
                   f"server, {result.failed} failed; store: {target}")
        if result.failed:
            sys.exit(1)

    @tiles.command("info")
    def info():
        """Show the configured tile store: where, what kind, zoom levels, bounds."""
        path = store_path(current_app.config)
        if path is None:
            click.echo("ROVER_WEB_MAP_TILES is unset: no basemap")
            return
        store = open_tile_store(path)
        try:
            if not store.exists():
                click.echo(f"{path}: no tiles there yet (the map shows no basemap)")
                return
            meta = store.metadata()
        finally:
            store.close()
        click.echo(f"{path} ({store.kind}): zoom {meta['minzoom']}-{meta['maxzoom']}, bounds {meta['bounds']}, "
                   f"attribution {meta['attribution']!r}")

    app.cli.add_command(tiles)
