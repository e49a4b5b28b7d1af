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


class SourceKey(NamedTuple):
    """What makes outputs share one ROS subscription: same topic, type and QoS."""

    topic: str
    msg_type: str
    qos: str


def source_key(key: StreamKey) -> SourceKey:
    return SourceKey(key.topic, key.msg_type, key.qos)


class FrameSource:
    """One ROS subscription feeding the producers of every output (size, quality) of its topic.

    Adaptive viewers move between outputs of one topic; one subscription for all of them keeps
    the executor's work (and the DDS copies of a large raw image) at one per message.
    """

    def __init__(self, key: SourceKey):
        self.key = key
        self.subscription: Any = None
        self._producers: list[FrameProducer] = []
        self._latest: tuple[int, Any] | None = None
        self._seq = 0
        self._lock = threading.Lock()

    def put(self, raw: Any) -> None:
        with self._lock:
            self._seq += 1
            seq = self._seq
            self._latest = (seq, raw)
            producers = list(self._producers)
        for producer in producers:
            producer.put(raw, seq)

    def attach(self, producer: FrameProducer) -> None:
        """A new output starts from the newest message, not from the next one."""
        with self._lock:
            self._producers.append(producer)
            if self._latest is not None:
                producer.put(self._latest[1], self._latest[0])

    def detach(self, producer: FrameProducer) -> int:
        """Remove `producer`; returns how many remain."""
        with self._lock:
            if producer in self._producers:
                self._producers.remove(producer)
            if not self._producers:
                self._latest = None
            return len(self._producers)


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

    def put(self, raw: Any, seq: int | None = None) -> None:
        """Keep the newest message; cheap on purpose, it runs on the ROS executor. `seq` numbers
        the message across every output of one topic (FrameSource), so a viewer moving to another
        output keeps its place."""
        with self._cond:
            if seq is not None and seq <= self._raw_seq:
                return  # never back to an older message
            self.arrivals.record()
            self._raw = raw
            self._raw_seq = self._raw_seq + 1 if seq is None else seq
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
