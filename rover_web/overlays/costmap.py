"""A costmap (nav_msgs/OccupancyGrid) checked, shrunk to a size cap and encoded compactly. Pure.

Nav2 publishes costs scaled to 0..100 (0 free, 1..98 inflated, 99 inscribed, 100 lethal) and -1
for unknown. The browser gets one byte per cell (unknown as 255), deflated and base64-encoded: a
400 x 400 costmap of mostly free space is a few kilobytes. A grid wider or taller than the cap is
shrunk by a whole factor keeping each block's highest cost, so a thin lethal wall never vanishes;
a grid beyond the hard cell cap, or whose data does not match its size, is skipped and counted.
"""

from __future__ import annotations

import base64
import math
import zlib
from dataclasses import dataclass

import numpy as np

UNKNOWN = 255


class BadGrid(ValueError):
    """A grid that cannot be drawn; the message is the reason counted."""


@dataclass(frozen=True)
class Grid:
    frame_id: str
    stamp: float
    width: int
    height: int
    resolution: float
    origin: tuple[float, float, float]
    cells: np.ndarray  # int8, row-major, row 0 at the origin


def check(grid: Grid, max_cells: int) -> None:
    if grid.width <= 0 or grid.height <= 0 or len(grid.cells) == 0:
        raise BadGrid("empty")
    if grid.width * grid.height > max_cells:
        raise BadGrid("too_large")
    if len(grid.cells) != grid.width * grid.height:
        raise BadGrid("size_mismatch")
    if not (math.isfinite(grid.resolution) and grid.resolution > 0) or not all(map(math.isfinite, grid.origin)):
        raise BadGrid("bad_header")


def shrink(cells: np.ndarray, width: int, height: int, max_side: int) -> tuple[np.ndarray, int]:
    """(uint8 (h, w) costs, factor): unknown as 255, blocks of factor x factor cells kept at their highest cost.

    Unknown counts below any known cost in a block, so a block with a wall in it shows the wall.
    """
    costs = np.asarray(cells, dtype=np.int8).reshape(height, width).astype(np.int16)
    factor = max(1, math.ceil(max(width, height) / max_side))
    if factor > 1:
        h, w = math.ceil(height / factor) * factor, math.ceil(width / factor) * factor
        padded = np.full((h, w), -1, dtype=np.int16)
        padded[:height, :width] = costs
        costs = padded.reshape(h // factor, factor, w // factor, factor).max(axis=(1, 3))
    out = np.clip(costs, 0, 100).astype(np.uint8)
    out[costs < 0] = UNKNOWN
    return out, factor


def encode(grid: Grid, topic: str, seq: int, max_side: int) -> dict:
    """One costmap of the `costmap` channel: size, placement and the deflated, base64 cells."""
    costs, factor = shrink(grid.cells, grid.width, grid.height, max_side)
    height, width = costs.shape
    return {"topic": topic, "seq": seq, "frame_id": grid.frame_id, "stamp": grid.stamp,
            "width": width, "height": height, "resolution": grid.resolution * factor, "factor": factor,
            "origin": [round(v, 6) for v in grid.origin], "encoding": "deflate-base64",
            "data": base64.b64encode(zlib.compress(costs.tobytes(), 6)).decode("ascii")}


def decode(data: str, width: int, height: int) -> np.ndarray:
    """The cells of an encoded costmap back as (height, width) uint8 (for tests and tools)."""
    return np.frombuffer(zlib.decompress(base64.b64decode(data)), dtype=np.uint8).reshape(height, width)
