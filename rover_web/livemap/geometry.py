"""World (map frame, metres) <-> floorplan image pixels, the way ROS map_server reads a map. Pure.

map_server's convention, which RViz and Nav2 share:
- `origin` [x, y, yaw] is the world pose of the image's *lower-left corner* (the outer corner of
  the bottom-left pixel, i.e. of occupancy cell (0, 0));
- world y points up while image rows count down from the top, so image row 0 is the far (+y) edge;
- one pixel is `resolution` metres on both axes.

Pixel coordinates here are continuous: (0, 0) is the top-left corner of the image and (W, H) its
bottom-right corner, so the centre of the pixel in column c, row r is (c + 0.5, r + 0.5). With a
zero origin yaw the conversion is exactly

    px = (x - ox) / resolution          row = H - (y - oy) / resolution

Origin yaw: map_server's docs say much of the stack ignores it, but Nav2's map_server copies it
into OccupancyGrid.info.origin, and RViz draws the grid rotated by it. We do the same: the image's
own axes are rotated by `origin_yaw` about the origin, so a non-zero yaw still maps world points
to the pixel RViz would show them on. Headings on the image are `yaw - origin_yaw`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


def wrap_angle(angle: float) -> float:
    """The same angle in (-pi, pi]."""
    wrapped = math.atan2(math.sin(angle), math.cos(angle))
    return math.pi if wrapped == -math.pi else wrapped


@dataclass(frozen=True)
class MapGeometry:
    width_px: int
    height_px: int
    resolution_m: float  # metres per image pixel, on both axes
    origin_x: float = 0.0
    origin_y: float = 0.0
    origin_yaw: float = 0.0

    def __post_init__(self):
        if self.width_px <= 0 or self.height_px <= 0:
            raise ValueError("a map image has at least one pixel on each side")
        if not (math.isfinite(self.resolution_m) and self.resolution_m > 0):
            raise ValueError("resolution must be a positive number of metres per pixel")
        if not all(math.isfinite(v) for v in (self.origin_x, self.origin_y, self.origin_yaw)):
            raise ValueError("origin must be finite")

    # --- sizes ---

    @property
    def width_m(self) -> float:
        return self.width_px * self.resolution_m

    @property
    def height_m(self) -> float:
        return self.height_px * self.resolution_m

    @property
    def cm_per_pixel(self) -> float:
        return self.resolution_m * 100.0

    def display_scale(self, cm_per_pixel: float) -> float:
        """Display pixels per image pixel when the map is shown at `cm_per_pixel`."""
        return self.cm_per_pixel / cm_per_pixel

    # --- conversions ---

    def world_to_pixel(self, x: float, y: float) -> tuple[float, float]:
        """Map-frame metres -> continuous image pixel coordinates (column, row from the top)."""
        dx, dy = x - self.origin_x, y - self.origin_y
        if self.origin_yaw:
            c, s = math.cos(self.origin_yaw), math.sin(self.origin_yaw)
            dx, dy = c * dx + s * dy, -s * dx + c * dy
        return dx / self.resolution_m, self.height_px - dy / self.resolution_m

    def pixel_to_world(self, px: float, py: float) -> tuple[float, float]:
        """Continuous image pixel coordinates -> map-frame metres."""
        u = px * self.resolution_m
        v = (self.height_px - py) * self.resolution_m
        if self.origin_yaw:
            c, s = math.cos(self.origin_yaw), math.sin(self.origin_yaw)
            u, v = c * u - s * v, s * u + c * v
        return self.origin_x + u, self.origin_y + v

    def yaw_to_image(self, yaw: float) -> float:
        """A map-frame heading as an angle on the image, counter-clockwise from its +column axis."""
        return wrap_angle(yaw - self.origin_yaw)

    def contains(self, x: float, y: float) -> bool:
        """True if the world point lies on the image (edges included)."""
        px, py = self.world_to_pixel(x, y)
        return 0.0 <= px <= self.width_px and 0.0 <= py <= self.height_px

    def cell_of(self, x: float, y: float) -> tuple[int, int] | None:
        """(column, row) of the image pixel under a world point, or None off the image."""
        px, py = self.world_to_pixel(x, y)
        col, row = math.floor(px), math.floor(py)
        if 0 <= col < self.width_px and 0 <= row < self.height_px:
            return col, row
        return None

    def to_display(self, x: float, y: float, cm_per_pixel: float) -> tuple[float, float]:
        """Map-frame metres -> pixels of the image drawn at `cm_per_pixel`."""
        px, py = self.world_to_pixel(x, y)
        scale = self.display_scale(cm_per_pixel)
        return px * scale, py * scale

    def from_display(self, dx: float, dy: float, cm_per_pixel: float) -> tuple[float, float]:
        scale = self.display_scale(cm_per_pixel)
        return self.pixel_to_world(dx / scale, dy / scale)
