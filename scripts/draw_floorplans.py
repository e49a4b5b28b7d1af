"""Draw the floorplans shipped in map_files/ (run it again after changing a plan; output is deterministic).

Each plan is laid out in map metres and drawn with the map_server conventions rover_web reads them
with (rover_web.map_geometry), as an occupancy image: free space 254, walls and furniture 0,
outside the building 205 (unknown). Writes the image, a map_server yaml, a waypoint file, and
map_files/all_maps.json listing both plans:

    .venv/bin/python scripts/draw_floorplans.py
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from rover_web.livemap.geometry import MapGeometry  # noqa: E402

FREE, WALL, UNKNOWN = 254, 0, 205
OUT = ROOT / "map_files"


class Plan:
    def __init__(self, geometry: MapGeometry):
        self.g = geometry
        self.image = Image.new("L", (geometry.width_px, geometry.height_px), UNKNOWN)
        self.draw = ImageDraw.Draw(self.image)

    def rect(self, x0: float, y0: float, x1: float, y1: float, value: int) -> None:
        """Fill the world rectangle [x0, x1] x [y0, y1] (metres)."""
        (c0, r0), (c1, r1) = self.g.world_to_pixel(x0, y1), self.g.world_to_pixel(x1, y0)
        self.draw.rectangle([round(c0), round(r0), round(c1) - 1, round(r1) - 1], fill=value)

    def wall(self, x0: float, y0: float, x1: float, y1: float, thickness: float = 0.2) -> None:
        """A straight wall between two points (horizontal or vertical), centred on the line."""
        h = thickness / 2
        self.rect(min(x0, x1) - h, min(y0, y1) - h, max(x0, x1) + h, max(y0, y1) + h, WALL)

    def door(self, x0: float, y0: float, x1: float, y1: float, thickness: float = 0.2) -> None:
        """Cut an opening into a wall along the given segment."""
        h = thickness / 2 + 0.01
        self.rect(min(x0, x1) - (h if x0 == x1 else 0), min(y0, y1) - (h if y0 == y1 else 0),
                  max(x0, x1) + (h if x0 == x1 else 0), max(y0, y1) + (h if y0 == y1 else 0), FREE)

    def block(self, x: float, y: float, w: float, d: float) -> None:
        """Furniture or a pillar: a solid w x d rectangle centred at (x, y)."""
        self.rect(x - w / 2, y - d / 2, x + w / 2, y + d / 2, WALL)


def basement() -> tuple[Plan, list[dict]]:
    """A building basement: a long east-west corridor, a north-south one, rooms off both."""
    plan = Plan(MapGeometry(800, 480, 0.05, -2.0, -1.5, 0.0))  # 40 m x 24 m
    plan.rect(0, 0, 36, 21, FREE)
    for x0, y0, x1, y1 in ((0, 0, 36, 0), (0, 21, 36, 21), (0, 0, 0, 21), (36, 0, 36, 21)):
        plan.wall(x0, y0, x1, y1, 0.3)
    # corridor walls (corridor y 9..12 and x 16..19), leaving the crossing open
    for x0, x1 in ((0, 16), (19, 36)):
        plan.wall(x0, 9, x1, 9)
        plan.wall(x0, 12, x1, 12)
    for y0, y1 in ((0, 9), (12, 21)):
        plan.wall(16, y0, 16, y1)
        plan.wall(19, y0, 19, y1)
    # rooms: south of the corridor, then north
    plan.wall(8, 0, 8, 9)
    plan.wall(27, 0, 27, 9)
    plan.wall(6, 12, 6, 21)
    plan.wall(28, 12, 28, 21)
    plan.wall(28, 16.5, 36, 16.5)
    for x0, x1, y in ((3, 4.2, 9), (11, 12.2, 9), (22, 23.2, 9), (31, 32.2, 9),
                      (2.5, 3.7, 12), (10, 11.2, 12), (22, 23.2, 12), (31, 32.2, 12)):
        plan.door(x0, y, x1, y)
    plan.door(28, 18.5, 28, 19.7)
    plan.door(30, 16.5, 31.2, 16.5)
    # the north-south corridor ends at the stairs; the elevator closes the east end of the main one
    plan.rect(16.2, 20.0, 18.8, 20.85, WALL)
    plan.rect(35.0, 9.1, 35.85, 11.9, WALL)
    # pillars in the corridors
    for x in (5.0, 10.5, 24.5, 30.0):
        plan.block(x, 10.5 + (1.2 if x < 16 else -1.2), 0.4, 0.4)
    plan.block(17.5, 4.5, 0.4, 0.4)
    # furniture: mail room shelves, lab benches, boiler, workbench, lounge sofas, storage racks
    plan.block(1.0, 4.5, 0.6, 6.0)
    plan.block(6.5, 2.0, 2.0, 0.8)
    for y in (2.5, 5.5):
        plan.block(23.0, y, 6.0, 0.9)
    plan.block(33.0, 19.0, 3.0, 2.4)
    plan.block(33.5, 14.0, 2.0, 1.0)
    plan.block(11.0, 18.5, 4.0, 0.9)
    plan.block(9.0, 15.5, 0.9, 2.0)
    for x in (1.5, 3.0, 4.5):
        plan.block(x, 18.5, 0.5, 3.5)
    waypoints = [
        {"name": "Dock", "x": 2.0, "y": 10.5, "yaw": 0.0},
        {"name": "Mail Room", "x": 4.0, "y": 5.0, "yaw": -math.pi / 2},
        {"name": "Lab B12", "x": 23.0, "y": 4.0, "yaw": 0.0},
        {"name": "Workshop", "x": 30.5, "y": 14.5, "yaw": 0.0},
        {"name": "Boiler Room", "x": 30.0, "y": 19.0, "yaw": 0.0},
        {"name": "Lounge", "x": 12.0, "y": 15.5, "yaw": math.pi / 2},
        {"name": "Storage", "x": 3.5, "y": 15.0, "yaw": math.pi},
        {"name": "Stairs", "x": 17.5, "y": 19.0, "yaw": math.pi / 2},
        {"name": "Elevator", "x": 34.0, "y": 10.5, "yaw": 0.0},
    ]
    return plan, waypoints


def lab() -> tuple[Plan, list[dict]]:
    """A robotics lab: benches along the walls, a fenced test arena, a charging corner."""
    plan = Plan(MapGeometry(480, 360, 0.025, -6.0, -4.5, 0.0))  # 12 m x 9 m, centred on the origin
    plan.rect(-5.6, -4.1, 5.6, 4.1, FREE)
    for x0, y0, x1, y1 in ((-5.6, -4.1, 5.6, -4.1), (-5.6, 4.1, 5.6, 4.1), (-5.6, -4.1, -5.6, 4.1),
                           (5.6, -4.1, 5.6, 4.1)):
        plan.wall(x0, y0, x1, y1, 0.25)
    plan.door(-5.6, -0.6, -5.6, 0.6, 0.25)
    # benches: a row along the north wall, one along the south wall
    for x in (-4.0, -1.6, 0.8):
        plan.block(x, 3.55, 2.0, 0.8)
    plan.block(-2.5, -3.6, 4.0, 0.7)
    # the test arena: a fence with a gate on its west side
    plan.wall(1.5, -2.5, 5.0, -2.5, 0.05)
    plan.wall(1.5, 2.0, 5.0, 2.0, 0.05)
    plan.wall(5.0, -2.5, 5.0, 2.0, 0.05)
    plan.wall(1.5, -2.5, 1.5, -0.6, 0.05)
    plan.wall(1.5, 0.6, 1.5, 2.0, 0.05)
    plan.block(3.8, 0.8, 0.5, 0.5)  # an obstacle in the arena
    plan.block(-0.5, 0.0, 0.5, 0.5)  # a pillar
    plan.block(-5.1, -3.5, 0.6, 0.6)  # the charger
    waypoints = [
        {"name": "Door", "x": -4.8, "y": 0.0, "yaw": 0.0},
        {"name": "Charger", "x": -4.3, "y": -3.0, "yaw": math.pi},
        {"name": "Bench 2", "x": -1.6, "y": 2.6, "yaw": math.pi / 2},
        {"name": "Arena gate", "x": 1.0, "y": 0.0, "yaw": 0.0},
        {"name": "Arena centre", "x": 3.0, "y": -0.5, "yaw": 0.0},
    ]
    return plan, waypoints


def map_server_yaml(image: str, g: MapGeometry) -> str:
    return (f"image: {image}\nmode: trinary\nresolution: {g.resolution_m}\n"
            f"origin: [{g.origin_x}, {g.origin_y}, {g.origin_yaw}]\n"
            "negate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.25\n")


def write_waypoints(path: Path, waypoints: list[dict]) -> None:
    rounded = [dict(w, yaw=math.trunc(w["yaw"] * 1e6) / 1e6) for w in waypoints]  # stays within [-pi, pi]
    path.write_text(json.dumps({"frame_id": "map", "waypoints": rounded}, indent=2) + "\n")


def main() -> None:
    (OUT / "basement").mkdir(parents=True, exist_ok=True)
    (OUT / "lab").mkdir(parents=True, exist_ok=True)

    plan, waypoints = basement()
    plan.image.save(OUT / "basement" / "basement.png", optimize=True)
    (OUT / "basement" / "basement.yaml").write_text(map_server_yaml("basement.png", plan.g))
    write_waypoints(OUT / "basement" / "basement_waypoints.json", waypoints)
    basement_g = plan.g

    plan, waypoints = lab()
    plan.image.save(OUT / "lab" / "lab.pgm")
    (OUT / "lab" / "lab.yaml").write_text(map_server_yaml("lab.pgm", plan.g))
    write_waypoints(OUT / "lab" / "lab_waypoints.json", waypoints)

    catalog = {
        # The campus rover's format: the image and its yaml parameters inline.
        "Science Hall Basement": {
            "files": {"path": "basement/",
                      "png_file": {"file_name": "basement.png", "cm_per_pixel": round(basement_g.cm_per_pixel, 9)},
                      "waypoint_file": "basement_waypoints.json"},
            "yaml_parameters": {"resolution": basement_g.resolution_m,
                                "origin": [basement_g.origin_x, basement_g.origin_y, basement_g.origin_yaw]},
        },
        # A standard map_server yaml with a PGM image, as map_saver writes them.
        "Robotics Lab": {
            "files": {"path": "lab/", "yaml_file": "lab.yaml", "waypoint_file": "lab_waypoints.json"},
        },
    }
    (OUT / "all_maps.json").write_text(json.dumps(catalog, indent=4) + "\n")
    print(f"wrote {OUT}/all_maps.json, basement/ and lab/")


if __name__ == "__main__":
    main()
