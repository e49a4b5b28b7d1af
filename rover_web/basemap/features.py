"""Drawn basemaps: GeoJSON files of land, water, paths and buildings the map renders itself. Pure Python.

A folder (ROVER_WEB_MAP_GEOJSON_DIR, default map_files/basemap/) of `<name>.geojson` files, each a
FeatureCollection whose features say what they are in `properties.kind` (KINDS) and whose top
level may carry `name`, `attribution` and `license` (GeoJSON allows such foreign members). The map
draws them under its grid with the style in static/js/gps/gps_map.js; the credit line shows the
attribution. Files are checked when read: a broken one is left out with a warning, never served.
"""

from __future__ import annotations

import functools
import json
import logging
import math
import os
import re
import tempfile
from pathlib import Path

from rover_web.config import repo_path
from rover_web.web.api_messages import explain, text_of
from rover_web.web.validate import InvalidInput, loads_strict

log = logging.getLogger(__name__)

KINDS = ("land", "water", "park", "wetland", "sand", "building", "pier", "road", "path", "shore")
GEOMETRIES = ("Point", "MultiPoint", "LineString", "MultiLineString", "Polygon", "MultiPolygon")
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9_-]{0,63}\Z")
MAX_FILE_BYTES = 20 * 1024 * 1024
MAX_FEATURES = 20000
MAX_POSITIONS = 500000
SUFFIX = ".geojson"


class BadFeatures(ValueError):
    """A GeoJSON file that cannot be a drawn basemap; the message names the feature and the field."""


def folder(config) -> Path | None:
    return repo_path(config.get("ROVER_WEB_MAP_GEOJSON_DIR"))


def _positions(coords, depth: int, where: str, counter: list[int]):
    """Every [lng, lat] of a geometry's nested coordinates, checked."""
    if depth == 0:
        if not isinstance(coords, list) or len(coords) < 2 or len(coords) > 3:
            raise BadFeatures(explain("%(where)s: a position must be [lng, lat] or [lng, lat, alt]", where=where))
        if any(isinstance(v, bool) or not isinstance(v, (int, float)) for v in coords):
            raise BadFeatures(explain("%(where)s: a position must hold numbers", where=where))
        lng, lat = float(coords[0]), float(coords[1])
        if not (math.isfinite(lng) and math.isfinite(lat) and -180 <= lng <= 180 and -90 <= lat <= 90):
            raise BadFeatures(explain("%(where)s: [%(coords)s, %(coords2)s] is not a longitude in [-180, 180] and "
                                      "a latitude in [-90, 90]",
                                      where=where, coords=coords[0], coords2=coords[1]))
        counter[0] += 1
        if counter[0] > MAX_POSITIONS:
            raise BadFeatures(explain("more than %(max_positions)s positions: simplify the file first",
                                      max_positions=format(MAX_POSITIONS, ",")))
        yield lng, lat
        return
    if not isinstance(coords, list):
        raise BadFeatures(explain("%(where)s: coordinates must be arrays", where=where))
    for i, inner in enumerate(coords):
        yield from _positions(inner, depth - 1, f"{where}[{i}]", counter)


DEPTH = {"Point": 0, "MultiPoint": 1, "LineString": 1, "MultiLineString": 2, "Polygon": 2, "MultiPolygon": 3}


def check(collection) -> dict:
    """The collection, its bounds added (bbox), if it is a drawable basemap; BadFeatures otherwise."""
    if not isinstance(collection, dict) or collection.get("type") != "FeatureCollection":
        raise BadFeatures(explain("a basemap must be a GeoJSON FeatureCollection ({\"type\": \"FeatureCollection\", "
                                  "...})"))
    features = collection.get("features")
    if not isinstance(features, list) or not features:
        raise BadFeatures(explain("'features' must be a non-empty array"))
    if len(features) > MAX_FEATURES:
        raise BadFeatures(explain("%(count)s features; at most %(max_features)s",
                                  count=format(len(features), ","), max_features=format(MAX_FEATURES, ",")))
    for key in ("name", "attribution", "license"):
        if key in collection and not (isinstance(collection[key], str) and len(collection[key]) <= 500):
            raise BadFeatures(explain("'%(key)s' must be a string of at most 500 characters", key=key))
    counter = [0]
    west = south = math.inf
    east = north = -math.inf
    for i, feature in enumerate(features):
        where = f"features[{i}]"
        if not isinstance(feature, dict) or feature.get("type") != "Feature":
            raise BadFeatures(explain("%(where)s: not a GeoJSON Feature", where=where))
        props = feature.get("properties")
        kind = props.get("kind") if isinstance(props, dict) else None
        if kind not in KINDS:
            raise BadFeatures(explain("%(where)s.properties.kind must be one of %(kinds)s; got %(kind)s",
                                      where=where, kinds=', '.join(KINDS), kind=repr(kind)))
        geometry = feature.get("geometry")
        gtype = geometry.get("type") if isinstance(geometry, dict) else None
        if gtype not in GEOMETRIES:
            raise BadFeatures(explain("%(where)s.geometry.type must be one of %(geometries)s; got %(gtype)s",
                                      where=where, geometries=', '.join(GEOMETRIES), gtype=repr(gtype)))
        for lng, lat in _positions(geometry.get("coordinates"), DEPTH[gtype], f"{where}.geometry.coordinates",
                                   counter):
            west, east, south, north = min(west, lng), max(east, lng), min(south, lat), max(north, lat)
    return {**collection, "bbox": [west, south, east, north]}


def parse(data: bytes, where: str) -> dict:
    if len(data) > MAX_FILE_BYTES:
        raise BadFeatures(explain("%(where)s: larger than %(value)s MB",
                                  where=where, value=MAX_FILE_BYTES // (1024 * 1024)))
    try:
        collection = loads_strict(data)
    except InvalidInput as exc:
        raise BadFeatures(explain("%(where)s: %(why)s", where=where, why=text_of(exc))) from None
    try:
        return check(collection)
    except BadFeatures as exc:
        raise BadFeatures(explain("%(where)s: %(why)s", where=where, why=text_of(exc))) from None


@functools.lru_cache(maxsize=16)
def _read(path: str, mtime_ns: int, size: int) -> dict | None:
    """A memo of one file's checked contents: the same file (path, time, size) reads the same."""
    try:
        return parse(Path(path).read_bytes(), path)
    except (OSError, BadFeatures) as exc:
        log.warning("basemap %s left out: %s", path, exc)
        return None


class FeatureFolder:
    """The drawn basemaps of one folder, each read and checked once per change of the file."""

    def __init__(self, root: Path):
        self.root = root

    def names(self) -> list[str]:
        if not self.root.is_dir():
            return []
        return sorted(p.name[:-len(SUFFIX)] for p in self.root.iterdir()
                      if p.name.endswith(SUFFIX) and NAME.match(p.name[:-len(SUFFIX)]) and p.is_file())

    def get(self, name: str) -> dict | None:
        """The checked collection, or None for an unknown name or a file that is not a valid basemap."""
        if not NAME.match(name):
            return None
        path = self.root / f"{name}{SUFFIX}"
        try:
            stat = path.stat()
        except OSError:
            return None
        return _read(str(path), stat.st_mtime_ns, stat.st_size)

    def sources(self, url_of) -> list[dict]:
        """What the page's GeoJSON sources need: name, url, attribution, bounds; valid files only."""
        found = []
        for name in self.names():
            collection = self.get(name)
            if collection is not None:
                found.append({"name": name, "url": url_of(name), "attribution": collection.get("attribution", ""),
                              "bounds": collection["bbox"]})
        return found

    def write(self, name: str, collection: dict, *, replace: bool = False) -> Path:
        """Store a checked collection as <name>.geojson, atomically; FileExistsError unless replace."""
        if not NAME.match(name):
            raise BadFeatures(explain("%(name)s is not a basemap name: letters, digits, '_' and '-', at most 64",
                                      name=repr(name)))
        self.root.mkdir(parents=True, exist_ok=True)
        path = self.root / f"{name}{SUFFIX}"
        if path.exists() and not replace:
            raise FileExistsError(f"{path} exists; pass --force to replace it")
        fd, tmp = tempfile.mkstemp(dir=self.root, prefix=f".{name}.", suffix=".part")
        try:
            with os.fdopen(fd, "w") as fh:
                json.dump({k: v for k, v in collection.items() if k != "bbox"}, fh, separators=(",", ":"))
            os.replace(tmp, path)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
        return path


def feature_folder(config) -> FeatureFolder | None:
    root = folder(config)
    return FeatureFolder(root) if root is not None else None
