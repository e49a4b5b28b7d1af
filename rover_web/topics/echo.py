"""Echoing any topic to browsers: measured rate and bandwidth, throttled decoding, the SSE frames. Pure Python.

One TopicEcho per viewed topic is fed the serialized messages by a raw ROS subscription: every
message is counted (rate, bandwidth) but only a few a second are deserialized and converted to
JSON, and that work is shared by every viewer of the topic. A 30 Hz camera topic therefore costs
a byte count per frame, not a decode.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from rover_web.events.hub import encode


class TrafficMeter:
    """Arrival times and sizes over the last `window_s`; rate and bandwidth over the span they cover."""

    def __init__(self, window_s: float = 5.0, max_samples: int = 4096):
        self.window_s = window_s
        self.count = 0
        self.bytes_total = 0
        self.last_size: int | None = None
        self._samples: deque[tuple[float, int]] = deque(maxlen=max_samples)
        self._lock = threading.Lock()

    def record(self, size: int, now: float | None = None) -> None:
        now = time.monotonic() if now is None else now
        with self._lock:
            self.count += 1
            self.bytes_total += size
            self.last_size = size
            self._samples.append((now, size))

    def snapshot(self, now: float | None = None) -> dict:
        now = time.monotonic() if now is None else now
        with self._lock:
            recent = [(t, s) for t, s in self._samples if now - t <= self.window_s]
            count, total, last_size = self.count, self.bytes_total, self.last_size
            last = self._samples[-1][0] if self._samples else None
        rate = bandwidth = 0.0
        if len(recent) >= 2 and recent[-1][0] > recent[0][0]:
            span = recent[-1][0] - recent[0][0]
            rate = (len(recent) - 1) / span
            if now - recent[-1][0] > 2.0 / rate:
                span = now - recent[0][0]  # gone quiet: let the numbers fall instead of freezing
                rate = (len(recent) - 1) / span
            # Each interval carries the message that ends it (ros2 topic bw does the same).
            bandwidth = sum(s for _, s in recent[1:]) / span
        return {
            "count": count,
            "bytes_total": total,
            "rate_hz": round(rate, 3),
            "bandwidth_bps": round(bandwidth, 1),
            "size_bytes": last_size,
            "age_s": None if last is None else round(max(0.0, now - last), 3),
        }


def clip_strings(value: Any, max_chars: int) -> Any:
    """Long strings inside a message dict become {truncated, length, head}, like long arrays."""
    if isinstance(value, str):
        if len(value) > max_chars:
            return {"truncated": True, "length": len(value), "head": value[:max_chars]}
        return value
    if isinstance(value, dict):
        return {k: clip_strings(v, max_chars) for k, v in value.items()}
    if isinstance(value, list):
        return [clip_strings(v, max_chars) for v in value]
    return value


class EchoClosed(RuntimeError):
    pass


class TopicEcho:
    """The newest serialized message of one topic, decoded at most `max_hz` times a second."""

    def __init__(self, topic: str, type_name: str, decode: Callable[[bytes], dict], max_hz: float,
                 max_chars: int = 2000):
        self.topic = topic
        self.type_name = type_name
        self.qos = ""
        self._decode = decode
        self.min_interval_s = 1.0 / max_hz
        self.max_chars = max_chars
        self.meter = TrafficMeter()
        self.subscription: Any = None
        self.decodes = 0
        self._cond = threading.Condition()
        self._decode_lock = threading.Lock()
        self._raw: bytes | None = None
        self._raw_seq = 0
        self._sample: tuple[int, dict | None, str | None] = (0, None, None)  # seq, message, error
        self._decoded_at = -float("inf")
        self._closed = False
        # Callables given every serialized message (the plots: rover_web/plot/). Replaced, never
        # mutated, so put() reads it without a lock.
        self.listeners: tuple[Callable[[bytes], None], ...] = ()

    def put(self, serialized: bytes) -> None:
        """From the ROS callback: count it, keep it, wake the viewers. No decoding here."""
        self.meter.record(len(serialized))
        for listener in self.listeners:
            listener(serialized)
        with self._cond:
            self._raw = serialized
            self._raw_seq += 1
            self._cond.notify_all()

    @property
    def seq(self) -> int:
        with self._cond:
            return self._raw_seq

    def wait_newer(self, after_seq: int, timeout_s: float) -> bool:
        """True once a message newer than `after_seq` arrived; False on timeout; EchoClosed when stopped."""
        deadline = time.monotonic() + timeout_s
        with self._cond:
            while not self._closed and self._raw_seq <= after_seq:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return False
                self._cond.wait(remaining)
            if self._closed:
                raise EchoClosed(self.topic)
            return True

    @property
    def next_decode_at(self) -> float:
        """When sample() will next decode a newer message (monotonic seconds)."""
        return self._decoded_at + self.min_interval_s * 0.9

    def sample(self, now: float | None = None) -> tuple[int, dict | None, str | None]:
        """(seq, fields, error) of a recent message: the newest, unless one was decoded too recently."""
        with self._decode_lock:  # one decode at a time; the others then reuse its result
            now = time.monotonic() if now is None else now
            with self._cond:
                raw, seq = self._raw, self._raw_seq
            current = self._sample
            if raw is None or seq == current[0] or now - self._decoded_at < self.min_interval_s * 0.9:
                return current
            try:
                fields, error = clip_strings(self._decode(raw), self.max_chars), None
            except Exception as exc:  # a message the installed type cannot read: say so, keep going
                fields, error = None, f"cannot decode a {self.type_name} message: {exc}"
            self.decodes += 1
            self._decoded_at = now
            self._sample = (seq, fields, error)
            return self._sample

    def close(self) -> None:
        with self._cond:
            self._closed = True
            self._raw = None
            self._cond.notify_all()


def echo_event(echo: TopicEcho, kind: str, sample=None) -> bytes:
    """An SSE frame without an id: a reconnecting browser wants the newest message, not a replay."""
    data = {"topic": echo.topic, "type": echo.type_name, "qos": echo.qos, "max_hz": round(1 / echo.min_interval_s, 3),
            "stats": echo.meter.snapshot()}
    if sample is not None:
        data["seq"], data["msg"], data["error"] = sample
    return f"event: {kind}\ndata: {encode(data)}\n\n".encode()
