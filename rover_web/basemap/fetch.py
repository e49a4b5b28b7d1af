"""Filling a tile store from a tile server: the area and zoom checks, the download, the loop."""

from __future__ import annotations

import math
import time
import urllib.error
import urllib.request
from collections.abc import Callable
from dataclasses import dataclass

import click

from .tile_store import MAX_ZOOM, MBTiles, image_format, tile_count, tile_ranges

DEFAULT_MAX_TILES = 5000
USER_AGENT = "rover_web-tiles-fetch/0.1 (offline basemap for a robot GUI)"


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
        raise click.BadParameter(f"need -180 <= W < E <= 180 (an area across the antimeridian: fetch it in two "
                                 f"parts); got W={west}, E={east}")
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
