"""A time code the simulated camera draws into each frame, and its reader: glass-to-glass frame age.

The sender's wall-clock time in ms, its 32 low bits, as two rows of large black and white cells in
the bottom-left corner. Each row is: a white and a black cell (the reader's reference levels),
16 data bits (most significant first), an even-parity cell and a closing white cell. A cell is
1/24 of the image's width, square, so the code scales with the image: it survives JPEG at low
quality, a video codec at a low bitrate and scaling to half size or less, because the reader
samples only each cell's middle and compares it with the reference cells of its own row.

Pure numpy: no ROS. `read()` gives the full time in ms, the high bits taken from the receiver's
clock (the 32 low bits wrap every 49.7 days; sender and receiver clocks must agree to well within
that, and for a meaningful age, to within a few ms: the bench runs both on one machine).
"""

from __future__ import annotations

import time

import numpy as np

CELLS_PER_WIDTH = 24
ROW_BITS = 16
ROW_CELLS = 2 + ROW_BITS + 2  # white, black, 16 bits, parity, white
MIN_WIDTH = 96  # below this the cells would be under 4 pixels: no code is drawn
MIN_CONTRAST = 64  # grey levels between the reference cells, else the code is not there
WRAP = 1 << 32


def _layout(width: int, height: int) -> tuple[float, float, float]:
    """Cell size and the code's top-left corner, in pixels of an image of this size."""
    cell = width / CELLS_PER_WIDTH
    return cell, cell / 2, height - 2 * cell - cell / 2


def _row_cells(bits16: int) -> list[int]:
    bits = [(bits16 >> (ROW_BITS - 1 - i)) & 1 for i in range(ROW_BITS)]
    return [1, 0, *bits, sum(bits) % 2, 1]


def draw(image: np.ndarray, stamp_ms: int) -> None:
    """Draw the 32 low bits of stamp_ms into an H×W×3 uint8 image, in place."""
    height, width = image.shape[:2]
    if width < MIN_WIDTH or height < width / CELLS_PER_WIDTH * 3:
        return
    cell, x0, y0 = _layout(width, height)
    low = int(stamp_ms) % WRAP
    for row, bits16 in enumerate((low >> 16, low & 0xFFFF)):
        top, bottom = round(y0 + row * cell), round(y0 + (row + 1) * cell)
        for col, bit in enumerate(_row_cells(bits16)):
            left, right = round(x0 + col * cell), round(x0 + (col + 1) * cell)
            image[top:bottom, left:right] = 255 if bit else 0


def read_low_bits(image: np.ndarray) -> int | None:
    """The 32 bits drawn by draw(), or None if the image carries no readable code."""
    height, width = image.shape[:2]
    if width < MIN_WIDTH // 2:
        return None
    luma = image.astype(np.float32) @ np.array([0.299, 0.587, 0.114], np.float32) if image.ndim == 3 \
        else image.astype(np.float32)
    cell, x0, y0 = _layout(width, height)
    inset = cell / 4  # the middle half of each cell: away from the codec's blurred edges

    def level(row: int, col: int) -> float:
        top, left = y0 + row * cell, x0 + col * cell
        patch = luma[int(top + inset):max(int(top + cell - inset), int(top + inset) + 1),
                     int(left + inset):max(int(left + cell - inset), int(left + inset) + 1)]
        return float(patch.mean()) if patch.size else float("nan")

    value = 0
    for row in range(2):
        levels = [level(row, col) for col in range(ROW_CELLS)]
        white, black = levels[0], levels[1]
        if not white - black >= MIN_CONTRAST:  # also false for nan
            return None
        threshold = (white + black) / 2
        bits = [1 if v > threshold else 0 for v in levels]
        if bits[-1] != 1 or sum(bits[2:2 + ROW_BITS]) % 2 != bits[2 + ROW_BITS]:
            return None
        for bit in bits[2:2 + ROW_BITS]:
            value = (value << 1) | bit
    return value


def read(image: np.ndarray, now_ms: int | None = None) -> int | None:
    """The sender's wall-clock time in ms drawn into `image` (RGB, H×W×3), or None: the 32 low bits
    from the image, the rest from the receiver's clock (`now_ms`, default time.time()), taking the
    candidate nearest to it."""
    low = read_low_bits(image)
    if low is None:
        return None
    now = int(time.time() * 1000) if now_ms is None else int(now_ms)
    candidate = (now - now % WRAP) + low
    return min((candidate - WRAP, candidate, candidate + WRAP), key=lambda t: abs(t - now))
