"""One camera stream shared by every viewer: the latest frame, encoded once, on demand. Pure Python.

The pattern is Miguel Grinberg's flask-video-streaming (one producer, many viewers, a slow viewer
skips frames) with one change: nothing encodes on the ROS executor thread. The subscription
callback only keeps a reference to the newest message (`put`, microseconds). The first viewer
that wants a frame newer than the one it has encodes the newest message, in its own request
thread; viewers that ask meanwhile wait for that encode instead of starting their own. So each
message is encoded at most once whatever the number of viewers, messages nobody asked for in
time are never encoded, and a viewer that falls behind simply gets the newest frame next.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any, NamedTuple

from rover_web.ros.topic_stats import TopicStats

from .imaging import Jpeg


class StreamKey(NamedTuple):
    """What makes two viewers share a stream: same topic, type, QoS and output."""

    topic: str
    msg_type: str
    qos: str
    width: int | None
    height: int | None
    quality: int


class StreamClosed(RuntimeError):
    """The producer stopped (last viewer left long ago, or the app shuts down)."""


class FrameProducer:
    def __init__(self, key: StreamKey, encode: Callable[[Any], Jpeg]):
        self.key = key
        self._encode = encode
        self._cond = threading.Condition()
        self._raw: Any = None
        self._raw_seq = 0
        self._frame: Jpeg | None = None
        self._frame_seq = 0
        self._encoding = False
        self._closed = False
        self.subscription: Any = None  # the ROS subscription feeding put(), kept by whoever made it
        self.arrivals = TopicStats(key.topic, key.msg_type)
        self.encodes = 0  # JPEG encodes (and error frames) actually run
        self.passthroughs = 0  # compressed JPEGs sent as they came
        self.errors = 0
        self.last_error: str | None = None
        self.encoded_seqs: deque[int] = deque(maxlen=4096)  # which messages were encoded, for tests
        self._encode_s: deque[float] = deque(maxlen=512)
        self.created_monotonic = time.monotonic()

    # --- producer side (ROS callback thread) ---

    def put(self, raw: Any) -> None:
        """Keep the newest message; cheap on purpose, it runs on the ROS executor."""
        self.arrivals.record()
        with self._cond:
            self._raw = raw
            self._raw_seq += 1
            self._cond.notify_all()

    # --- viewer side (request threads) ---

    def next_frame(self, after_seq: int, timeout_s: float) -> tuple[int, Jpeg] | None:
        """The newest frame after `after_seq` as (seq, jpeg); None on timeout; StreamClosed when stopped.

        A viewer passes the seq of the last frame it sent, so it never gets the same frame twice
        and never a queue of old ones.
        """
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while True:
                if self._closed:
                    raise StreamClosed("stream stopped")
                if self._raw_seq > after_seq:
                    if self._frame is not None and self._frame_seq == self._raw_seq:
                        return self._frame_seq, self._frame  # the newest is encoded already
                    if not self._encoding:
                        self._encoding = True  # this viewer encodes the newest message
                        raw, seq = self._raw, self._raw_seq
                        break
                    if self._frame is not None and self._frame_seq > after_seq:
                        return self._frame_seq, self._frame  # newer than ours while the next is encoding
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._cond.wait(remaining)
        frame = None
        try:
            frame = self._encode(raw)
        finally:
            with self._cond:
                self._encoding = False
                if frame is not None:
                    self._frame, self._frame_seq = frame, seq
                    self.encoded_seqs.append(seq)
                    if frame.passthrough:
                        self.passthroughs += 1
                    else:
                        self.encodes += 1
                        self._encode_s.append(frame.encode_s)
                    if frame.error is not None:
                        self.errors += 1
                        self.last_error = frame.error
                self._cond.notify_all()
        return seq, frame

    def latest(self) -> tuple[int, Jpeg] | None:
        with self._cond:
            return None if self._frame is None else (self._frame_seq, self._frame)

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._raw = None
            self._cond.notify_all()

    @property
    def closed(self) -> bool:
        return self._closed

    # --- inspection ---

    def stats(self) -> dict:
        with self._cond:
            times = sorted(self._encode_s)
            frame = self._frame
            stats = {
                "received": self._raw_seq,
                "encodes": self.encodes,
                "passthroughs": self.passthroughs,
                "errors": self.errors,
                "last_error": self.last_error,
            }
        arrivals = self.arrivals.snapshot(stale_after_s=2.0)
        stats["rate_hz"] = arrivals["rate_hz"]
        stats["age_s"] = arrivals["age_s"]
        stats["jpeg_bytes"] = len(frame.data) if frame else None
        stats["frame_size"] = [frame.width, frame.height] if frame else None
        if times:
            stats["encode_ms"] = {
                "mean": round(1000 * sum(times) / len(times), 3),
                "median": round(1000 * times[len(times) // 2], 3),
                "p99": round(1000 * times[min(len(times) - 1, int(len(times) * 0.99))], 3),
                "samples": len(times),
            }
        else:
            stats["encode_ms"] = None
        return stats
