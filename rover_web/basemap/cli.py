"""`flask --app rover_web tiles fetch|import|info`: fill and inspect the offline basemap, without ROS."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from flask import Flask, current_app
from flask.cli import AppGroup

from .features import feature_folder
from .features import folder as features_folder
from .fetch import DEFAULT_MAX_TILES, TooManyTiles, check_url_template, fetch_tiles, parse_bbox, parse_zoom
from .importer import ImportRefused, import_geojson, import_mbtiles
from .source import store_path
from .tile_store import TileStoreError, open_tile_store, tile_count


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

    @tiles.command("import")
    @click.argument("path", type=click.Path(dir_okay=False, path_type=Path))
    @click.option("--out", type=click.Path(path_type=Path), default=None,
                  help="where to: the tile store for an .mbtiles file (default ROVER_WEB_MAP_TILES), the drawn-basemap "
                       "folder for a .geojson file (default ROVER_WEB_MAP_GEOJSON_DIR)")
    @click.option("--name", default=None, help="a GeoJSON basemap's name (default: the file's name)")
    @click.option("--attribution", default="", help="credit line shown on the map (default: the file's own)")
    @click.option("--force", is_flag=True, help="replace tiles, or a GeoJSON basemap, that are already there")
    def import_(path, out, name, attribution, force):
        """Import a basemap made elsewhere: an MBTiles file of raster tiles, or a GeoJSON file of land and water."""
        suffix = path.suffix.lower()
        try:
            if suffix == ".mbtiles":
                target = out or store_path(current_app.config)
                if target is None:
                    raise click.UsageError("ROVER_WEB_MAP_TILES is unset: name a store with --out")
                store = open_tile_store(target, writable=True)
                try:
                    result = import_mbtiles(path, store, force=force, attribution=attribution,
                                            report=lambda line: click.echo(line, err=True))
                finally:
                    store.close()
                click.echo(f"done: {result.imported} tiles imported, {result.kept} already there; store: {target}")
            elif suffix in (".geojson", ".json"):
                root = out or features_folder(current_app.config)
                if root is None:
                    raise click.UsageError("ROVER_WEB_MAP_GEOJSON_DIR is unset: name a folder with --out")
                folder = feature_folder({"ROVER_WEB_MAP_GEOJSON_DIR": str(root)})
                written = import_geojson(path, folder, name=name, attribution=attribution, force=force)
                click.echo(f"done: {written} (drawn on the GPS map)")
            else:
                raise click.UsageError(f"{path}: import takes an .mbtiles file or a .geojson (or .json) file")
        except (ImportRefused, TileStoreError) as exc:
            raise click.ClickException(str(exc)) from None

    @tiles.command("info")
    def info():
        """Show the basemaps: the tile store (where, what kind, zoom levels, bounds) and the drawn ones."""
        click.echo(_store_line(store_path(current_app.config)))
        drawn = feature_folder(current_app.config)
        for name in drawn.names() if drawn is not None else ():
            collection = drawn.get(name)
            click.echo(f"drawn basemap {name} ({drawn.root}): " + (
                f"{len(collection['features'])} features, bounds {collection['bbox']}, attribution "
                f"{collection.get('attribution', '')!r}" if collection else "not valid, left out (see the log)"))

    app.cli.add_command(tiles)


def _store_line(path: Path | None) -> str:
    if path is None:
        return "ROVER_WEB_MAP_TILES is unset: no tile basemap"
    store = open_tile_store(path)
    try:
        if not store.exists():
            return f"{path}: no tiles there yet"
        meta = store.metadata()
    finally:
        store.close()
    return (f"{path} ({store.kind}): zoom {meta['minzoom']}-{meta['maxzoom']}, bounds {meta['bounds']}, "
            f"attribution {meta['attribution']!r}")
