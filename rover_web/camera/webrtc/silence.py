"""Whether a WebRTC viewer's next frame is worth encoding: not while the browser has gone quiet.
Pure Python (clock injected).

The browser's RTCP (receiver reports, REMB, NACK) is the only sign the sender has that its packets
arrive. aiortc negotiates no transport-wide feedback, so reports come 0.5 to 1.5 s apart (aiortc's
receiver; the radio profile showed gaps up to 1.3 s) and a 500 ms stall cannot be told from a
quiet second. An outage can: through the radio's 3 s outage the video kept being encoded and sent
at the rate before it, the link dropped it, and the frames sent between the outage's end and the
first feedback after it queued behind what TCP had held, so the keyframe the browser then asked
for came 0.6 s late (BENCHMARKS.md, 2026-11-27). So once no feedback has come for SILENCE_S, frames
are taken at the viewer's pace but neither encoded nor sent, except one every PROBE_S: a browser
that sends feedback only when media arrives must get some to answer, and a link that is back
carries it. The first feedback after that sends everything again; the browser's NACKs and PLIs
(feedback.py) bring the keyframe it needs.
"""

from __future__ import annotations

import time
from collections.abc import Callable

SILENCE_S = 2.0  # longer than any gap between a browser's reports, shorter than an outage worth holding
PROBE_S = 1.0


class Silence:
    def __init__(self, clock: Callable[[], float] = time.monotonic):
        self._clock = clock
        self._heard: float | None = None  # the last feedback; None: none yet (the stream is starting)
        self._probed = -float("inf")
        self.held = 0  # frames not sent because the browser was quiet

    def heard(self) -> None:
        """Any RTCP packet from the browser."""
        self._heard = self._clock()

    def send(self) -> bool:
        """Whether the next frame should be encoded and sent."""
        now = self._clock()
        if self._heard is None or now - self._heard <= SILENCE_S:
            return True
        if now - self._probed >= PROBE_S:
            self._probed = now
            return True
        self.held += 1
        return False
