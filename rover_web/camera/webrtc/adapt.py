"""How far one viewer's video steps down when its link is poor. Pure Python (clock injected).

aiortc's VP8 and H.264 encoders follow the browser's congestion feedback themselves: each REMB
packet sets the encoder's `target_bitrate` (clamped by aiortc to 250 kbit/s .. 1.5 Mbit/s for
VP8), and the next frame is encoded at that rate. At a low rate a full-size picture at full frame
rate turns into mush, so this policy lowers the frame rate, then the size, when the target stays
below what the current level needs, and climbs back when it stays comfortably above the next one.

What a level "needs" is a fixed number of bits per pixel (BITS_PER_PIXEL: about what VP8 in
realtime mode needs for a watchable picture; 640×480 at 30 fps needs 460 kbit/s) times pixels per
second. The bitrate judged is the browser's own estimate (REMB) when one came: aiortc's encoder
never goes below its floor, so below it a lower frame rate and size are what keep frames whole. Stepping down is quick
(DOWN_AFTER_S), stepping up slow (UP_AFTER_S) and with headroom (UP_HEADROOM), so the level does
not flap on a link that wavers around one threshold.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

BITS_PER_PIXEL = 0.05
DOWN_AFTER_S = 1.0
UP_AFTER_S = 4.0
UP_HEADROOM = 1.25


@dataclass(frozen=True)
class Level:
    scale: float  # of each side
    fps_fraction: float  # of the camera's (or the asked) frame rate


# Two thirds first: on wifi-edge the browser's estimate sat between what 20 and 30 fps need for
# seconds after each decrease (it climbs back by ~30 kbit/s a second), and halving went to 15 fps.
LEVELS = (Level(1.0, 1.0), Level(1.0, 2 / 3), Level(1.0, 0.5), Level(0.5, 0.5), Level(0.5, 1 / 3))


def even(value: float) -> int:
    """YUV 4:2:0 halves each side for colour: encoders want even sizes."""
    return max(2, int(value) // 2 * 2)


@dataclass(frozen=True)
class Output:
    width: int
    height: int
    fps: float
    level: int


class AdaptPolicy:
    def __init__(self, max_fps: float, *, clock: Callable[[], float] = time.monotonic):
        self.max_fps = max_fps
        self.level = 0
        self._clock = clock
        self._below_since: float | None = None
        self._above_since: float | None = None
        self.changes = 0

    def needs_bps(self, level: int, width: int, height: int) -> float:
        chosen = LEVELS[level]
        pixels = width * chosen.scale * height * chosen.scale
        return BITS_PER_PIXEL * pixels * self.max_fps * chosen.fps_fraction

    def update(self, target_bps: float | None, width: int, height: int) -> Output:
        """The output for a source of width×height given the encoder's current target bitrate
        (None: not known yet, keep the level)."""
        now = self._clock()
        if target_bps is not None:
            if self.level < len(LEVELS) - 1 and target_bps < self.needs_bps(self.level, width, height):
                self._above_since = None
                if self._below_since is None:
                    self._below_since = now
                if now - self._below_since >= DOWN_AFTER_S:
                    self.level += 1
                    self.changes += 1
                    self._below_since = None
            elif self.level > 0 and target_bps >= UP_HEADROOM * self.needs_bps(self.level - 1, width, height):
                self._below_since = None
                if self._above_since is None:
                    self._above_since = now
                if now - self._above_since >= UP_AFTER_S:
                    self.level -= 1
                    self.changes += 1
                    self._above_since = None
            else:
                self._below_since = self._above_since = None
        chosen = LEVELS[self.level]
        if chosen.scale >= 1.0:
            out_w, out_h = width, height
        else:
            out_w, out_h = even(width * chosen.scale), even(height * chosen.scale)
        return Output(out_w, out_h, self.max_fps * chosen.fps_fraction, self.level)
