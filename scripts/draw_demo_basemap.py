"""Draw the demo's drawn basemap, map_files/basemap/benderson_park.geojson (output is deterministic).

A schematic of the simulator's water at Nathan Benderson Park, FL, not a survey: a rowing lake
around the demo geofence (map_files/geofence.geojson, with at least 50 m to spare on every side), a
shore path, the park around it and land to the edge of the demo area. The open datasets on the
package registries (Natural Earth as world-atlas on npm, @geo-maps' land polygons from
OpenStreetMap's coastline) stop at the sea coast: this inland lake, about 10 km from Sarasota Bay,
is plain land in them, so at a boat's scale they show nothing. For a true shoreline, import a
GeoJSON or MBTiles your team made (`flask tiles import`, docs/basemap.md).

    .venv/bin/python scripts/draw_demo_basemap.py
"""

from __future__ import annotations

import json
import math
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "map_files" / "basemap" / "benderson_park.geojson"

AREA = (-82.475, 27.358, -82.425, 27.391)  # W, S, E, N: the area docs/basemap.md fetches tiles for
LAKE_CENTRE = (-82.45035, 27.37445)
LAKE_HALF = (0.0096, 0.0060)        # degrees of longitude and latitude from the centre to a side
CORNER = 0.0030                      # degrees: the radius of the lake's rounded corners
METRES_PER_DEG_LAT = 111_195.0


def rounded_rectangle(centre, half, radius, grow_m=0.0, steps=12):
    """A closed ring, counter-clockwise, `grow_m` metres outside the lake's outline."""
    cx, cy = centre
    k = math.cos(math.radians(cy))  # a degree of longitude is shorter than one of latitude
    grow_lat = grow_m / METRES_PER_DEG_LAT
    r_lat = radius + grow_lat
    r_lng = (radius + grow_lat) / k
    hx, hy = half[0] - radius / k, half[1] - radius
    ring = []
    for qx, qy, start in ((1, -1, -90), (1, 1, 0), (-1, 1, 90), (-1, -1, 180)):
        ox, oy = cx + qx * hx, cy + qy * hy
        for i in range(steps + 1):
            a = math.radians(start + 90 * i / steps)
            ring.append([round(ox + r_lng * math.cos(a), 7), round(oy + r_lat * math.sin(a), 7)])
    ring.append(ring[0])
    return ring


def feature(kind, name, gtype, coordinates):
    return {"type": "Feature", "properties": {"kind": kind, "name": name},
            "geometry": {"type": gtype, "coordinates": coordinates}}


def draw() -> dict:
    w, s, e, n = AREA
    lake = rounded_rectangle(LAKE_CENTRE, LAKE_HALF, CORNER)
    return {
        "type": "FeatureCollection",
        "name": "Nathan Benderson Park (schematic)",
        "attribution": "Demo area: a schematic drawing, not a survey (rover_web, MIT)",
        "license": "MIT",
        "features": [
            feature("land", "land", "Polygon", [[[w, s], [e, s], [e, n], [w, n], [w, s]]]),
            feature("park", "park", "Polygon", [rounded_rectangle(LAKE_CENTRE, LAKE_HALF, CORNER, grow_m=180)]),
            feature("water", "rowing lake", "Polygon", [lake]),
            feature("path", "shore path", "LineString", rounded_rectangle(LAKE_CENTRE, LAKE_HALF, CORNER, grow_m=40)),
        ],
    }


def main() -> None:
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(draw(), indent=1) + "\n")
    print(f"wrote {OUT.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
