"""When a WebRTC viewer's encoder is given a new bitrate. Pure Python (clock injected).

aiortc's VP8 encoder cannot change its bitrate in place (FFmpeg's libvpx wrapper reads it only when
the encoder opens): a target more than 10 % from the encoder's own makes aiortc open a new
encoder, and a new encoder's first frame is a keyframe, five to ten times a normal frame. The
browser's estimate (REMB) moves by a few per cent with nearly every packet; passed on as it came,
it opened 179 encoders in 55 s through the radio profile, three keyframes a second on a 0.5 Mbit/s
link, and the frames behind them were a second old (BENCHMARKS.md, 2026-11-27).

So the encoder's bitrate moves in steps: down at once when the wanted rate falls below
DOWN_RATIO of it (the link pushed back: sending more than it carries builds a queue), but not
again within DOWN_INTERVAL_S of the last step down unless it falls below half; up only when the wanted rate has stayed
UP_RATIO above it for UP_HOLD_S. UP_RATIO must stay below 1.5 × the link share (1.125 at 0.75):
the browser never estimates more than 1.5 × what arrives, so the wanted rate is never more than
that above what the encoder sends, and a larger step would never be taken (at 1.2 the video stayed
near its start rate through wifi-edge).

It starts at aiortc's own 500 kbit/s and climbs at once until the link first pushes back (a slow
start, as TCP's), then held as above. A lower start (250 kbit/s) kept the radio's first stall from
queueing more than the link could drain (its frame age p99 outside stalls 0.29 s against 0.97 s),
but the video then stayed at about 21 fps on links that carry 30, loopback included (BENCHMARKS.md,
2026-11-27): not understood yet, so not taken.
"""

from __future__ import annotations

import time
from collections.abc import Callable

DOWN_RATIO = 0.85
DOWN_INTERVAL_S = 1.0
UP_RATIO = 1.1
UP_HOLD_S = 1.0
START_BPS = 500_000  # aiortc's DEFAULT_BITRATE for VP8


class EncoderBitrate:
    def __init__(self, start: int = START_BPS, *, clock: Callable[[], float] = time.monotonic):
        self.current = start
        self.changes = 0
        self._clock = clock
        self._last_down = -float("inf")
        self._above_since: float | None = None

    def update(self, wanted: int) -> int:
        """The bitrate to give the encoder now that `wanted` is what the link allows."""
        now = self._clock()
        current = self.current
        if wanted < DOWN_RATIO * current:
            self._above_since = None
            if wanted < 0.5 * current or now - self._last_down >= DOWN_INTERVAL_S:
                self._last_down = now
                return self._set(wanted)
        elif wanted > UP_RATIO * current:
            if self._above_since is None:
                self._above_since = now
            # Until the link first pushes back the climb is not held (a slow start, as TCP's):
            # held from a low start, a 20 Mbit/s link was still at 21 fps after 40 s.
            if self._last_down == -float("inf") or now - self._above_since >= UP_HOLD_S:
                return self._set(wanted)
        else:
            self._above_since = None
        return current

    def _set(self, wanted: int) -> int:
        self.changes += 1
        self.current, self._above_since = wanted, None
        return wanted
