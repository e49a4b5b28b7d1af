"""A nav_msgs/OccupancyGrid drawn as a greyscale floorplan, the way map_saver would write it. Pure.

Cell values are -1 (unknown) or 0..100 (occupancy probability in percent). Like Nav2's map_saver
with its default thresholds, free cells (<= 25) are near-white 254, occupied cells (>= 65) black 0
and unknown cells 205 grey; the few cells in between are shaded by their probability (188..91), so
no shade of them can be mistaken for unknown. Grid row 0 is the map's bottom edge (the origin side)
and image row 0 is the top, so the grid is flipped vertically.
"""

from __future__ import annotations

import io

import numpy as np

FREE_MAX = 25
OCCUPIED_MIN = 65
FREE_GREY = 254
OCCUPIED_GREY = 0
UNKNOWN_GREY = 205


def grid_to_image(data: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width) uint8 image, image row 0 at the top, from the row-major cell values."""
    cells = np.asarray(data, dtype=np.int8).reshape(height, width)
    image = np.full((height, width), UNKNOWN_GREY, dtype=np.uint8)
    known = (cells >= 0) & (cells <= 100)
    between = known & (cells > FREE_MAX) & (cells < OCCUPIED_MIN)
    image[known & (cells <= FREE_MAX)] = FREE_GREY
    image[known & (cells >= OCCUPIED_MIN)] = OCCUPIED_GREY
    image[between] = np.round(254.0 * (1.0 - cells[between].astype(np.float32) / 100.0)).astype(np.uint8)
    return np.ascontiguousarray(np.flipud(image))


def image_to_png(image: np.ndarray) -> bytes:
    from PIL import Image  # when a map is first drawn, not at start (issue 32: idle RSS)

    out = io.BytesIO()
    Image.fromarray(image).save(out, "PNG", compress_level=3)
    return out.getvalue()
