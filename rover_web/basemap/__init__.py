"""The offline basemap: tiles served by the app itself (GET /tiles/z/x/y) and `flask tiles fetch`.

By default the map fetches nothing from the internet. An operator fills a local store once, while
online, with `flask --app rover_web tiles fetch --bbox W,S,E,N --zoom A-B --url TEMPLATE`, and the
map then shows those tiles in the field. The store is the folder or .mbtiles file named by
ROVER_WEB_MAP_TILES (relative paths from the repository root, like ROVER_WEB_MAPS_FILE; default
map_files/tiles); the page asks only this app for tiles.

Modules: tile_store (folder and MBTiles stores, tile math), source (the installed store and the
page's raster source), fetch (filling a store from a tile server), cli (`flask tiles fetch|info`,
registered before and without the ROS node), routes (GET /tiles/<z>/<x>/<y>).
"""

from __future__ import annotations

from rover_web.core.state import Rover

from . import routes
from .cli import init_cli

__all__ = ["init_app", "init_cli"]


def init_app(app, rover: Rover) -> None:
    app.register_blueprint(routes.bp)
