"""python -m rover_web.livemap.check_maps FILE: read a floorplan catalog in full (every image decoded,
every keep-out area checked with shapely) and print one JSON line: the images' sizes, or the error.

Run by the server at start (map_files.load_catalog_checked_apart), so that the libraries the checks
need are loaded in this short-lived process and not kept in the server's memory."""

from __future__ import annotations

import json
import sys

from rover_web.config import ConfigError

from .map_files import load_catalog


def main(argv: list[str]) -> int:
    try:
        catalog = load_catalog(argv[0])
    except ConfigError as exc:
        print(json.dumps({"error": str(exc)}))
        return 0
    sizes = {str(d.image_path.resolve()): [d.geometry.width_px, d.geometry.height_px]
             for d in catalog.values() if d.image_path is not None}
    print(json.dumps({"sizes": sizes}))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
