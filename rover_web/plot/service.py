"""Plots: series of numeric fields on the topic browser's shared subscriptions, and the `plot` channel.

A series is (topic, field). Its topic is subscribed through TopicBrowser (the same shared
subscription, viewer count and caps as an echo); every message's bytes are queued by the
subscription callback and decoded off the executor, once per message for all fields of that topic,
by the plot loop, which also sends the new points of every series as one `plot` event.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque

from rover_web.core.state import Rover
from rover_web.topics.service import TopicBrowser

from . import msgs
from .field import FieldError, finite, parse_path, read_number
from .series import SeriesRing

log = logging.getLogger(__name__)

TICK_S = 0.1  # new points go to browsers at most 10 times a second
RAW_QUEUE = 5000  # messages waiting for the plot loop per topic (a 1 kHz topic over a slow tick)
MAX_SERIES = 64


class TooManySeries(RuntimeError):
    pass


class _Series:
    def __init__(self, field: str, keep: int):
        self.field = field
        self.steps = parse_path(field)
        self.ring = SeriesRing(keep)
        self.used_at = time.monotonic()


class _PlotTopic:
    """One subscribed topic: its raw message queue and the series read from it."""

    def __init__(self, key: tuple[str, str], echo):
        self.key = key
        self.echo = echo
        self.decode = msgs.deserializer(key[1])
        self.raw: deque[tuple[float, bytes]] = deque(maxlen=RAW_QUEUE)
        self.series: dict[str, _Series] = {}

    def put(self, serialized: bytes) -> None:
        self.raw.append((time.time(), serialized))  # from the ROS callback: no decoding here


def series_id(topic: str, field: str) -> str:
    return f"{topic} {field}"  # a topic name has no spaces


class Plots:
    def __init__(self, rover: Rover):
        self.rover = rover
        self.keep = rover.config["ROVER_WEB_PLOT_KEEP_POINTS"]
        self.idle_s = rover.config["ROVER_WEB_PLOT_IDLE_S"]
        self._topics: dict[tuple[str, str], _PlotTopic] = {}
        self._lock = threading.Lock()
        self.decode_errors = 0
        self.plotting = threading.Event()  # the plot loop sleeps while nothing is plotted

    @property
    def browser(self) -> TopicBrowser:
        return self.rover.feature(TopicBrowser)

    def series(self, key: tuple[str, str], field: str) -> _Series:
        """The series of `field` on topic `key` (topic, type), started now if new.

        FieldError when the type has no number there; the topic browser's EchoRefused when its
        subscription cannot be had (caps, shutdown).
        """
        steps = parse_path(field)
        msgs.numeric_kind(key[1], steps)
        with self._lock:
            plot_topic = self._topics.get(key)
            if plot_topic is not None and field in plot_topic.series:
                series = plot_topic.series[field]
                series.used_at = time.monotonic()
                return series
            if sum(len(p.series) for p in self._topics.values()) >= MAX_SERIES:
                raise TooManySeries(f"{MAX_SERIES} series are plotted already")
            if plot_topic is None:
                echo = self.browser.acquire(key)
                plot_topic = self._topics[key] = _PlotTopic(key, echo)
                echo.listeners = (*echo.listeners, plot_topic.put)
            series = plot_topic.series[field] = _Series(field, self.keep)
            self.plotting.set()
            return series

    def tick(self) -> None:
        """Decode what arrived, append to the rings, send the new points, end idle series."""
        now = time.monotonic()
        fresh: dict[str, dict] = {}
        with self._lock:
            topics = list(self._topics.values())
        for plot_topic in topics:
            batch = []
            while plot_topic.raw:
                batch.append(plot_topic.raw.popleft())
            if batch:
                self._decode(plot_topic, batch, fresh)
        if fresh:
            self.rover.hub.emit("plot", {"series": fresh})
        self._end_idle(now)

    def _decode(self, plot_topic: _PlotTopic, batch: list[tuple[float, bytes]], fresh: dict) -> None:
        with self._lock:
            series = list(plot_topic.series.values())
        points: dict[str, list[tuple[float, float]]] = {s.field: [] for s in series}
        for stamp, raw in batch:
            try:
                msg = plot_topic.decode(raw)
            except Exception:
                self.decode_errors += 1
                continue
            for s in series:
                try:
                    value = read_number(msg, s.steps)
                except (TypeError, ValueError):
                    value = None
                if finite(value):
                    points[s.field].append((round(stamp, 4), value))
                else:
                    s.ring.skipped_nonfinite += 1  # NaN, inf or absent: skipped, never sent as NaN
        topic = plot_topic.key[0]
        for s in series:
            if points[s.field]:
                s.ring.add_many(points[s.field])
                fresh[series_id(topic, s.field)] = {"t": [p[0] for p in points[s.field]],
                                                    "v": [p[1] for p in points[s.field]]}

    def _end_idle(self, now: float) -> None:
        released = []
        with self._lock:
            for key, plot_topic in list(self._topics.items()):
                for field, s in list(plot_topic.series.items()):
                    if now - s.used_at > self.idle_s:
                        del plot_topic.series[field]
                if not plot_topic.series:
                    del self._topics[key]
                    plot_topic.echo.listeners = tuple(f for f in plot_topic.echo.listeners if f != plot_topic.put)
                    released.append(key)
            if not self._topics:
                self.plotting.clear()
        for key in released:
            self.browser.release(key)

    def active(self) -> list[dict]:
        with self._lock:
            return [{"topic": key[0], "type": key[1], "field": field, "points": len(s.ring)}
                    for key, p in self._topics.items() for field, s in p.series.items()]

    def close(self) -> None:
        with self._lock:
            keys = list(self._topics)
            self._topics.clear()
        for key in keys:
            try:
                self.browser.release(key)
            except Exception:
                log.exception("releasing the plot subscription of %s failed", key[0])


__all__ = ["FieldError", "Plots", "TooManySeries", "series_id"]
