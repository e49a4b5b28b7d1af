"""`flask --app rover_web tiles fetch|info`: fill and inspect the offline basemap, without ROS."""

from __future__ import annotations

import sys
from pathlib import Path

import click
from flask import Flask, current_app
from flask.cli import AppGroup

from .fetch import DEFAULT_MAX_TILES, TooManyTiles, check_url_template, fetch_tiles, parse_bbox, parse_zoom
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
