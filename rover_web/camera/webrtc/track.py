"""CameraTrack: one WebRTC viewer's video, the newest camera frame each time aiortc asks for one.

aiortc's RTCRtpSender calls `recv()` in a loop and encodes what it returns (in the loop's default
thread pool, so encoding never runs on the loop itself nor on the ROS executor). `recv` waits for a
frame newer than the last one sent (FrameProducer.next_frame, in our frame pool: it blocks), never
faster than the viewer's frame rate (AdaptPolicy), and builds the av.VideoFrame at the viewer's
size, in the pool too. A frame's pts is the time since the track's first frame, in 1/90000 s (the
RTP video clock), so a browser's jitter buffer sees real time between frames however many were
skipped.
"""

from __future__ import annotations

import asyncio
import fractions
import logging
import time
from collections.abc import Callable
from concurrent.futures import Executor

import av
from aiortc.mediastreams import MediaStreamError, MediaStreamTrack

from rover_web.camera.stream import FrameProducer, StreamClosed

from .adapt import AdaptPolicy, Output
from .frames import Picture

log = logging.getLogger(__name__)

VIDEO_CLOCK_HZ = 90000
TIME_BASE = fractions.Fraction(1, VIDEO_CLOCK_HZ)
# How long one wait for a frame blocks a pool thread before the track checks it is still live.
WAIT_S = 0.5


def to_video_frame(picture: Picture, out: Output) -> av.VideoFrame:
    frame = av.VideoFrame.from_ndarray(picture.data, format="rgb24" if picture.data.ndim == 3 else "gray")
    return frame.reformat(width=out.width, height=out.height, format="yuv420p")


class CameraTrack(MediaStreamTrack):
    kind = "video"

    def __init__(self, producer: FrameProducer, pool: Executor, policy: AdaptPolicy,
                 target_bitrate: Callable[[], int | None] = lambda: None):
        super().__init__()
        self.producer = producer
        self.policy = policy
        self.target_bitrate = target_bitrate
        self._pool = pool
        self._seq = 0
        self._started: float | None = None
        self._due = 0.0  # when the next frame may be taken
        self._last_pts = -1
        self.frames_sent = 0
        self.output: Output | None = None
        self.last_stamp = 0.0
        self.last_error: str | None = None

    async def recv(self) -> av.VideoFrame:
        loop = asyncio.get_running_loop()
        if self.output is not None:  # pace to the viewer's frame rate; the newest frame is taken after
            wait = self._due - time.monotonic()
            if wait > 0:
                await asyncio.sleep(wait)
        slot = time.monotonic()
        while True:
            if self.readyState != "live":
                raise MediaStreamError
            try:
                # One hand-off per frame: waiting, the adaptation and the conversion in one pool call
                # (on a loaded machine every thread wake-up costs; MJPEG's request thread has none).
                made = await loop.run_in_executor(self._pool, self._next_frame)
            except StreamClosed:
                self.stop()
                raise MediaStreamError from None
            if made is not None:
                break
        frame, picture = made
        if picture.error is not None and picture.error != self.last_error:
            log.warning("WebRTC stream of %s: %s", self.producer.key.topic, picture.error)
        self.last_error = picture.error
        now = time.monotonic()
        if self._started is None:
            self._started = now
        pts = int((now - self._started) * VIDEO_CLOCK_HZ)
        frame.pts = max(pts, self._last_pts + 1)  # strictly increasing, whatever the clock did
        frame.time_base = TIME_BASE
        self._last_pts = frame.pts
        # The next slot one period after this one's, not after this frame was made: timed from the
        # end of the conversion (and its wait for a camera frame newer than the last), 15 fps came
        # out as 13 and 30 as 24. A slot taken late moves the next no closer than half a period.
        period = 1.0 / self.output.fps
        self._due = max(self._due + period, slot + period / 2)
        self.last_stamp = picture.stamp
        self.frames_sent += 1
        return frame

    def _next_frame(self) -> tuple[av.VideoFrame, Picture] | None:
        """In the pool: the newest picture after the last one sent (None after WAIT_S without one),
        at the size and rate the adaptation says now."""
        got = self.producer.next_frame(self._seq, WAIT_S)
        if got is None:
            return None
        self._seq, picture = got
        self.output = self.policy.update(self.target_bitrate(), picture.width, picture.height)
        return to_video_frame(picture, self.output), picture
