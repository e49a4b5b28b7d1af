"""Plots: series of numeric fields on the topic browser's shared subscriptions, and the `plot` channel.

A series is (topic, field). Its topic is subscribed through TopicBrowser (the same shared
subscription, viewer count and caps as an echo); every message's bytes are queued by the
subscription callback and decoded off the executor, once per message for all fields of that topic,
by the plot loop, which also sends the new points of every series as one `plot` event.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque

from rover_web.core.state import Rover
from rover_web.topics.service import TopicBrowser
from rover_web.web.api_messages import explain

from . import msgs
from .field import FieldError, finite, parse_path, read_number
from .series import SeriesRing

log = logging.getLogger(__name__)

TICK_S = 0.1  # new points go to browsers at most 10 times a second
RAW_QUEUE = 5000  # messages waiting for the plot loop per topic (a 1 kHz topic over a slow tick)
RAW_QUEUE_BYTES = 8 << 20  # ... and at most this many of their bytes (oldest dropped)
MAX_SERIES = 64
# Bulk data, not numbers to plot: a 6 MB image decoded ten times a second for one field of its
# header was the cost (issue 27). Refused by type; any other message over
# ROVER_WEB_PLOT_MAX_MESSAGE_BYTES is dropped unread in the subscription callback.
NOT_PLOTTABLE = frozenset({
    "sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage", "sensor_msgs/msg/PointCloud2",
    "sensor_msgs/msg/PointCloud", "nav_msgs/msg/OccupancyGrid", "map_msgs/msg/OccupancyGridUpdate",
    "theora_image_transport/msg/Packet", "ffmpeg_image_transport_msgs/msg/FFMPEGPacket",
})


class TooManySeries(RuntimeError):
    pass


class NotPlottable(ValueError):
    """A type whose messages are bulk data (images, point clouds, maps): refused before subscribing."""


class _Series:
    def __init__(self, field: str, keep: int):
        self.field = field
        self.steps = parse_path(field)
        self.ring = SeriesRing(keep)
        self.used_at = time.monotonic()
        # Who asked for it lately (client key → when): a series counts against the share of each
        # client that polls it, and no longer once that client has not asked for PLOT_IDLE_S.
        self.users: dict[str, float] = {}


class _PlotTopic:
    """One subscribed topic: its raw message queue and the series read from it."""

    def __init__(self, key: tuple[str, str], echo, max_message_bytes: int):
        self.key = key
        self.echo = echo
        self.decode = msgs.deserializer(key[1])
        self.max_message_bytes = max_message_bytes
        self.raw: deque[tuple[float, bytes]] = deque()
        self.raw_bytes = 0
        self.oversize = 0  # messages dropped unread for their size
        self._raw_lock = threading.Lock()
        self.series: dict[str, _Series] = {}

    def put(self, serialized: bytes) -> None:
        """From the ROS callback: no decoding here, and nothing kept of a message over the size cap."""
        size = len(serialized)
        if size > self.max_message_bytes:
            self.oversize += 1
            return
        with self._raw_lock:
            self.raw.append((time.time(), serialized))
            self.raw_bytes += size
            while len(self.raw) > RAW_QUEUE or self.raw_bytes > RAW_QUEUE_BYTES:
                self.raw_bytes -= len(self.raw.popleft()[1])

    def take(self) -> list[tuple[float, bytes]]:
        with self._raw_lock:
            batch, self.raw, self.raw_bytes = list(self.raw), deque(), 0
        return batch


def check_plottable(type_name: str) -> None:
    if type_name in NOT_PLOTTABLE:
        raise NotPlottable(explain("%(type_name)s is bulk data (images, point clouds, maps), not numbers to plot; "
                                   "plot a topic of numbers, or view it in the camera or topic pages",
                                   type_name=type_name))


def oversize(plots: Plots, key: tuple[str, str]) -> int:
    """Messages of a plotted topic dropped unread for their size (0 when it is not plotted)."""
    plot_topic = plots._topics.get(key)
    return plot_topic.oversize if plot_topic is not None else 0


def series_id(topic: str, field: str) -> str:
    return f"{topic} {field}"  # a topic name has no spaces


class Plots:
    def __init__(self, rover: Rover):
        self.rover = rover
        self.keep = rover.config["ROVER_WEB_PLOT_KEEP_POINTS"]
        self.idle_s = rover.config["ROVER_WEB_PLOT_IDLE_S"]
        self.max_message_bytes = rover.config["ROVER_WEB_PLOT_MAX_MESSAGE_BYTES"]
        self.per_client = rover.config["ROVER_WEB_PLOT_SERIES_PER_CLIENT"]
        self._topics: dict[tuple[str, str], _PlotTopic] = {}
        self._lock = threading.Lock()
        self.decode_errors = 0
        self.plotting = threading.Event()  # the plot loop sleeps while nothing is plotted

    @property
    def browser(self) -> TopicBrowser:
        return self.rover.feature(TopicBrowser)

    def series(self, key: tuple[str, str], field: str, client: str | None = None) -> _Series:
        """The series of `field` on topic `key` (topic, type), started now if new, for `client`
        (web/streams.py's client_key: a user or an address; None counts against no share).

        NotPlottable for a type of bulk data; FieldError when the type has no number there;
        TooManySeries when all series, or this client's share of them, are taken; the topic
        browser's EchoRefused when its subscription cannot be had (caps, shutdown).
        """
        check_plottable(key[1])
        steps = parse_path(field)
        msgs.numeric_kind(key[1], steps)
        now = time.monotonic()
        with self._lock:
            plot_topic = self._topics.get(key)
            series = plot_topic.series.get(field) if plot_topic is not None else None
            if client is not None and (series is None or client not in series.users):
                held = self._held_by(client, now)
                if held >= self.per_client:
                    raise TooManySeries(explain("you plot %(held)s series already "
                                                "(ROVER_WEB_PLOT_SERIES_PER_CLIENT): close one, or wait %(idle_s)s "
                                                "s after you stop asking for it",
                                                held=held, idle_s=format(self.idle_s, "g")))
            if series is not None:
                series.used_at = now
                if client is not None:
                    series.users[client] = now
                return series
            if sum(len(p.series) for p in self._topics.values()) >= MAX_SERIES:
                raise TooManySeries(explain("%(max_series)s series are plotted already", max_series=MAX_SERIES))
            if plot_topic is None:
                echo = self.browser.acquire(key)
                plot_topic = self._topics[key] = _PlotTopic(key, echo, self.max_message_bytes)
                echo.listeners = (*echo.listeners, plot_topic.put)
            series = plot_topic.series[field] = _Series(field, self.keep)
            if client is not None:
                series.users[client] = now
            self.plotting.set()
            return series

    def _held_by(self, client: str, now: float) -> int:
        """How many series `client` asked for within the idle time (the lock held)."""
        return sum(1 for p in self._topics.values() for s in p.series.values()
                   if now - s.users.get(client, -math.inf) <= self.idle_s)

    def tick(self) -> None:
        """Decode what arrived, append to the rings, send the new points, end idle series."""
        now = time.monotonic()
        fresh: dict[str, dict] = {}
        with self._lock:
            topics = list(self._topics.values())
        for plot_topic in topics:
            batch = plot_topic.take()
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


__all__ = ["FieldError", "NotPlottable", "Plots", "TooManySeries", "check_plottable", "oversize", "series_id"]
