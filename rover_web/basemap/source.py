"""The installed basemap: the tile store ROVER_WEB_MAP_TILES names, and the raster source the page gets."""

from __future__ import annotations

from pathlib import Path

from rover_web.config import repo_path

from .features import feature_folder
from .tile_store import TileStoreError, open_tile_store

TILE_URL = "/tiles/{z}/{x}/{y}"
FEATURES_URL = "/basemap/{name}"


def store_path(config) -> Path | None:
    return repo_path(config.get("ROVER_WEB_MAP_TILES"))


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


def map_view(config) -> dict:
    """Where a GPS map opens and what it draws under it, from settings alone (no ROS: the hub's map too)."""
    return {
        "place": config["ROVER_WEB_MAP_PLACE_NAME"],
        "center": [config["ROVER_WEB_MAP_CENTER_LNG"], config["ROVER_WEB_MAP_CENTER_LAT"]],
        "zoom": config["ROVER_WEB_MAP_ZOOM"],
        "basemap": basemap(config),
        "features": features(config),
    }


def features(config) -> list[dict]:
    """The drawn (GeoJSON) basemaps the page adds as sources: [{name, url, attribution, bounds}]."""
    found = feature_folder(config)
    return found.sources(lambda name: FEATURES_URL.format(name=name)) if found is not None else []


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
