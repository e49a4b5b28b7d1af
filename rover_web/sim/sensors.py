"""What the simulated rover senses, from its floorplan: a ray-cast laser scan and Nav2-like costmaps. Pure.

The floorplan image is the world: dark pixels are walls. Costs follow Nav2's costmap_2d as it
publishes them on an OccupancyGrid: 100 on a wall, 99 within the robot's inscribed radius, then
an exponential fall to 1 at the inflation radius, 0 beyond.
"""

from __future__ import annotations

import io
import math
from dataclasses import dataclass

import numpy as np
from PIL import Image

WALL_BELOW = 100  # a pixel darker than this is a wall (the floorplans draw walls black, floors white)
LETHAL, INSCRIBED = 100, 99
DIAGONAL = math.sqrt(2)
# (row, column) offsets into a one-cell padding, and the step to each of the 8 neighbours.
NEIGHBOURS = ((0, 1, 1.0), (2, 1, 1.0), (1, 0, 1.0), (1, 2, 1.0),
              (0, 0, DIAGONAL), (0, 2, DIAGONAL), (2, 0, DIAGONAL), (2, 2, DIAGONAL))


@dataclass(frozen=True)
class Floorplan:
    walls: np.ndarray  # bool (rows, cols), row 0 at the map's bottom edge (the origin side), as a grid
    resolution: float
    origin_x: float
    origin_y: float

    @classmethod
    def from_definition(cls, definition) -> Floorplan:
        with Image.open(io.BytesIO(definition.png())) as image:
            grey = np.asarray(image.convert("L"))
        g = definition.geometry
        return cls(np.flipud(grey < WALL_BELOW).copy(), g.resolution_m, g.origin_x, g.origin_y)

    @property
    def shape(self) -> tuple[int, int]:
        return self.walls.shape

    def raycast(self, x: float, y: float, yaw: float, angles: np.ndarray, range_max: float) -> np.ndarray:
        """Range of each beam (angles relative to yaw) to the first wall, inf when none is within range_max."""
        steps = np.arange(self.resolution / 2, range_max, self.resolution / 2)
        theta = yaw + angles
        xs = x + np.cos(theta)[:, None] * steps[None, :]
        ys = y + np.sin(theta)[:, None] * steps[None, :]
        cols = np.floor((xs - self.origin_x) / self.resolution).astype(np.int64)
        rows = np.floor((ys - self.origin_y) / self.resolution).astype(np.int64)
        h, w = self.walls.shape
        inside = (cols >= 0) & (cols < w) & (rows >= 0) & (rows < h)
        hit = np.zeros(xs.shape, dtype=bool)
        hit[inside] = self.walls[rows[inside], cols[inside]]
        first = np.argmax(hit, axis=1)
        ranges = np.where(hit.any(axis=1), steps[first], np.inf)
        return ranges.astype(np.float32)

    def costs(self, inscribed_m: float = 0.18, inflation_m: float = 0.55, decay: float = 5.0) -> np.ndarray:
        """int8 (rows, cols) Nav2 costs of the whole floorplan, row 0 at the bottom."""
        reach = math.ceil(inflation_m / self.resolution)
        distance = np.where(self.walls, 0.0, np.inf)
        for _ in range(reach):  # a chamfer distance transform, in cells, out to the inflation radius
            padded = np.pad(distance, 1, constant_values=np.inf)
            h, w = distance.shape
            for dr, dc, step in NEIGHBOURS:
                np.minimum(distance, padded[dr:dr + h, dc:dc + w] + step, out=distance)
        metres = distance * self.resolution
        cost = np.zeros(distance.shape, dtype=np.int8)
        falling = (metres > inscribed_m) & (metres <= inflation_m)
        cost[falling] = np.clip(np.round(98 * np.exp(-decay * (metres[falling] - inscribed_m))), 1, 98)
        cost[metres <= inscribed_m] = INSCRIBED
        cost[self.walls] = LETHAL
        return cost


def window(costs: np.ndarray, plan: Floorplan, x: float, y: float, size_m: float) -> tuple[np.ndarray, float, float]:
    """The square of `costs` around (x, y), as a rolling local costmap: (cells, origin x, origin y).

    Cells off the floorplan are unknown (-1)."""
    n = max(1, round(size_m / plan.resolution))
    col0 = math.floor((x - plan.origin_x) / plan.resolution) - n // 2
    row0 = math.floor((y - plan.origin_y) / plan.resolution) - n // 2
    out = np.full((n, n), -1, dtype=np.int8)
    h, w = costs.shape
    r0, r1 = max(row0, 0), min(row0 + n, h)
    c0, c1 = max(col0, 0), min(col0 + n, w)
    if r0 < r1 and c0 < c1:
        out[r0 - row0:r1 - row0, c0 - col0:c1 - col0] = costs[r0:r1, c0:c1]
    return out, plan.origin_x + col0 * plan.resolution, plan.origin_y + row0 * plan.resolution


def footprint(x: float, y: float, yaw: float, half_m: float) -> list[tuple[float, float]]:
    """A square footprint of side 2 * half_m around the robot, in the map frame, turned with it."""
    c, s = math.cos(yaw), math.sin(yaw)
    corners = ((half_m, half_m), (-half_m, half_m), (-half_m, -half_m), (half_m, -half_m))
    return [(x + c * u - s * v, y + s * u + c * v) for u, v in corners]
