"""The floorplan's walls for the simulated robot: it stops or slides along them, never drives through. Pure Python.

The occupied cells of the map image (map_server's trinary reading: `negate`, `occupied_thresh`)
are grown by the robot's radius once at start, so each step is one array look-up. Unknown cells
and everything off the image are free: a robot that leaves the floorplan is on open ground, and one
placed inside a wall (a `--start` there) may drive out of it; only a step from free space into a
wall is refused.
"""

from __future__ import annotations

import math

import numpy as np
from PIL import Image

from rover_web.livemap.geometry import MapGeometry
from rover_web.livemap.map_files import MapDefinition
from rover_web.livemap.map_images import MAP_IMAGE_FORMATS

ROBOT_RADIUS_M = 0.2  # LiveMap's default robot is 35.4 cm across
STALL_AFTER_S = 5.0   # pushing this long with less than STALL_MOVE_M of progress: the way is blocked
STALL_MOVE_M = 0.1


def occupied_cells(image: np.ndarray, negate: bool, occupied_thresh: float) -> np.ndarray:
    """map_server's rule: occupancy p = (255 - v) / 255 (or v / 255 negated); occupied when p > thresh."""
    grey = image.astype(np.float32)
    p = grey / 255.0 if negate else (255.0 - grey) / 255.0
    return p > occupied_thresh


def grow(occupied: np.ndarray, radius_cells: int) -> np.ndarray:
    """Every cell within `radius_cells` of an occupied one (a disc), by shifting the grid."""
    grown = occupied.copy()
    h, w = occupied.shape
    for dr in range(-radius_cells, radius_cells + 1):
        for dc in range(-radius_cells, radius_cells + 1):
            if (dr or dc) and dr * dr + dc * dc <= radius_cells * radius_cells:
                src = occupied[max(0, -dr):h - max(0, dr), max(0, -dc):w - max(0, dc)]
                grown[max(0, dr):h - max(0, -dr), max(0, dc):w - max(0, -dc)] |= src
    return grown


class Walls:
    def __init__(self, geometry: MapGeometry, occupied: np.ndarray, radius_m: float = ROBOT_RADIUS_M):
        self.geometry = geometry
        self.blocked = grow(occupied, math.ceil(radius_m / geometry.resolution_m))

    @classmethod
    def of_map(cls, definition: MapDefinition, radius_m: float = ROBOT_RADIUS_M) -> Walls | None:
        """The walls of a floorplan from its image file; None for a map with no image on disk."""
        if definition.image_path is None:
            return None
        with Image.open(definition.image_path, formats=MAP_IMAGE_FORMATS) as image:
            grey = np.asarray(image.convert("L"))
        params = definition.yaml
        occupied = occupied_cells(grey, bool(params.get("negate", 0)), float(params.get("occupied_thresh", 0.65)))
        return cls(definition.geometry, occupied, radius_m)

    def is_blocked(self, x: float, y: float) -> bool:
        cell = self.geometry.cell_of(x, y)
        return cell is not None and bool(self.blocked[cell[1], cell[0]])

    def move(self, x0: float, y0: float, x1: float, y1: float) -> tuple[float, float]:
        """Where a step from (x0, y0) towards (x1, y1) ends: all the way, sliding along a wall, or short of it.

        Walked in cells, so a long step (a late tick) cannot jump a wall thinner than itself.
        """
        steps = max(1, math.ceil(math.hypot(x1 - x0, y1 - y0) / self.geometry.resolution_m))
        dx, dy = (x1 - x0) / steps, (y1 - y0) / steps
        x, y = x0, y0
        for i in range(steps):
            if not self.is_blocked(x + dx, y + dy) or self.is_blocked(x, y):
                x, y = (x1, y1) if i == steps - 1 else (x + dx, y + dy)
            elif not self.is_blocked(x + dx, y):
                x += dx
            elif not self.is_blocked(x, y + dy):
                y += dy
            else:
                break
        return x, y


class StallWatch:
    """Says when a robot that is trying to drive has made no headway for STALL_AFTER_S: a wall is in the way."""

    def __init__(self, after_s: float = STALL_AFTER_S, move_m: float = STALL_MOVE_M):
        self.after_s, self.move_m = after_s, move_m
        self._since: tuple[float, float, float] | None = None  # (x, y, time) where headway was last made

    def stalled(self, x: float, y: float, now: float, pushing: bool) -> bool:
        if not pushing:
            self._since = None
            return False
        if self._since is None or math.hypot(x - self._since[0], y - self._since[1]) >= self.move_m:
            self._since = (x, y, now)
            return False
        if now - self._since[2] >= self.after_s:
            self._since = None
            return True
        return False
