"""EventHub: the latest value of every channel, plus a small ring of events that must not be lost.

Producers (ROS callbacks, request threads) call `publish` (conflated: a newer value replaces an
older one) or `emit` (kept in a bounded ring with ids so `Last-Event-ID` can replay it). Each event
is serialised to its SSE frame exactly once, at publish time; a subscriber only keeps a cursor,
so a slow browser skips stale values instead of growing a queue, and memory does not depend on
the number or speed of clients. Pure Python: no Flask, no rclpy.
"""

from __future__ import annotations

import json
import math
import re
import threading
import time
from collections import deque
from collections.abc import Iterable
from typing import Any

from rover_web.web.api_messages import explain

CHANNEL_RE = re.compile(r"[a-z][a-z0-9_]{0,31}\Z")


def encode(data: Any) -> str:
    """Compact JSON; NaN and Infinity are refused because browsers cannot parse them."""
    return json.dumps(data, separators=(",", ":"), allow_nan=False)


def sse_frame(seq: int, channel: str, payload: str) -> bytes:
    return f"id: {seq}\nevent: {channel}\ndata: {payload}\n\n".encode()


class TooManyClients(RuntimeError):
    pass


class EventHub:
    def __init__(self, ring_size: int = 256, max_clients: int = 256):
        self._lock = threading.RLock()  # publish() re-enters it from publish_throttled and the flusher
        self._cond = threading.Condition(self._lock)  # subscribers wait on this one
        self._held = threading.Condition(self._lock)  # and only the flusher on this one
        self._seq = 0
        self._latest: dict[str, tuple[int, bytes, Any]] = {}
        self._ring: deque[tuple[int, str, bytes]] = deque(maxlen=ring_size)
        # The newest change as (seq, channel, frame): a client one change behind takes it as is.
        self._last_change: tuple[int, str, bytes] = (0, "", b"")
        self._channels: set[str] = set()
        self._clients = 0
        self._watching: dict[str, int] = {}  # channel -> open subscriptions that asked for it
        self._max_clients = max_clients
        self._closed = False
        self._throttle: dict[str, list] = {}  # channel -> [last publish time, held value or None]
        self._held_due: dict[str, float] = {}  # channel -> when its held value goes out
        self._flusher: threading.Thread | None = None
        self._listeners: list = []

    # --- producers ---

    def register(self, *channels: str) -> None:
        """Declare channels a page may ask for; unknown names in a request are an error."""
        for channel in channels:
            if not CHANNEL_RE.match(channel):
                raise ValueError(f"bad channel name {channel!r}")
        with self._cond:
            self._channels.update(channels)

    def publish(self, channel: str, data: Any) -> int:
        """Set the channel's latest value (conflated); returns its sequence number."""
        payload = encode(data)
        with self._cond:
            self._seq += 1
            frame = sse_frame(self._seq, channel, payload)
            self._latest[channel] = (self._seq, frame, data)
            self._last_change = (self._seq, channel, frame)
            self._cond.notify_all()
            self._notify_listeners()
            return self._seq

    def publish_throttled(self, channel: str, data: Any, max_hz: float) -> None:
        """Publish at most max_hz times a second, and always the latest value in the end.

        Values that arrive too soon are held, and the hub's one flusher thread sends the newest
        when the interval is up, so a robot that stops is shown stopped even when its final message
        came in a burst. (One thread for every channel: a timer thread per held value meant
        starting ~20 threads a second for each fast topic, on the joystick's path among others.)
        """
        interval = 1.0 / max_hz
        with self._lock:
            state = self._throttle.setdefault(channel, [-math.inf, None])
            now = time.monotonic()
            due = state[0] + interval
            if due > now:
                if state[1] is None:
                    self._held_due[channel] = due
                    self._wake_flusher()
                state[1] = (data,)
                return
            state[0] = now
            state[1] = None  # anything held is older than this value: it must not go out after it
            self._held_due.pop(channel, None)
            self.publish(channel, data)

    def _wake_flusher(self) -> None:
        if self._flusher is None:
            self._flusher = threading.Thread(target=self._flush_held, name="event-hub-flusher", daemon=True)
            self._flusher.start()
        else:
            self._held.notify()

    def _flush_held(self) -> None:
        """Sends each held value when its channel's interval is up; ends with the hub."""
        with self._lock:
            while not self._closed:
                if not self._held_due:
                    self._held.wait()
                    continue
                channel = min(self._held_due, key=self._held_due.__getitem__)
                wait = self._held_due[channel] - time.monotonic()
                if wait > 0:
                    self._held.wait(wait)
                    continue
                del self._held_due[channel]
                state = self._throttle[channel]
                held, state[1] = state[1], None
                if held is not None:
                    state[0] = time.monotonic()
                    self.publish(channel, held[0])

    def emit(self, channel: str, data: Any) -> int:
        """An event that must reach every client in order (not conflated), kept in the ring."""
        payload = encode(data)
        with self._cond:
            self._seq += 1
            frame = sse_frame(self._seq, channel, payload)
            self._ring.append((self._seq, channel, frame))
            self._last_change = (self._seq, channel, frame)
            self._cond.notify_all()
            self._notify_listeners()
            return self._seq

    def add_listener(self, wake) -> None:
        """`wake()` is called (under the hub lock, so it must be quick) after every change and on close."""
        with self._cond:
            self._listeners.append(wake)

    def _notify_listeners(self) -> None:
        for wake in self._listeners:
            wake()

    def latest(self, channel: str) -> Any:
        with self._cond:
            entry = self._latest.get(channel)
            return None if entry is None else entry[2]

    def close(self) -> None:
        """Wake every subscriber so its stream can end (shutdown)."""
        with self._cond:
            self._closed = True
            self._cond.notify_all()
            self._held.notify()
            self._notify_listeners()

    # --- consumers ---

    @property
    def channels(self) -> frozenset[str]:
        with self._cond:
            return frozenset(self._channels)

    @property
    def lock(self):
        """The hub's (reentrant) lock, for a consumer that must hold it around several polls."""
        return self._cond

    @property
    def last_change(self) -> tuple[int, str, bytes]:
        """The newest change as (seq, channel, frame); read it under `lock` with the cursors it is
        compared to (the Broadcaster's fast path)."""
        return self._last_change

    @property
    def client_count(self) -> int:
        with self._cond:
            return self._clients

    @property
    def closed(self) -> bool:
        return self._closed

    def subscribe(self, channels: Iterable[str], last_event_id: int | None = None) -> Subscription:
        with self._cond:
            if self._clients >= self._max_clients:
                raise TooManyClients(explain("%(clients)s event streams are open already", clients=self._clients))
            self._clients += 1
            channels = frozenset(channels)
            for channel in channels:
                self._watching[channel] = self._watching.get(channel, 0) + 1
        return Subscription(self, channels, last_event_id)

    def watchers(self, channel: str) -> int:
        """How many open streams asked for `channel`: a producer whose work only a watcher needs
        (the overlays' markers and scan) skips it at zero."""
        return self._watching.get(channel, 0)

    def _release(self, channels: frozenset[str] = frozenset()) -> None:
        with self._cond:
            self._clients -= 1
            for channel in channels:
                self._watching[channel] = self._watching.get(channel, 1) - 1


class Subscription:
    """One client's cursor into the hub. Not thread-safe: one stream owns it."""

    def __init__(self, hub: EventHub, channels: frozenset[str], last_event_id: int | None):
        self._hub = hub
        self.channels = channels
        self.cursor = 0  # the last seq this client has been given (or skipped); the hub's lock guards it
        # Replay only ring events the client missed; conflated values always come as a snapshot.
        self._ring_cursor = last_event_id if last_event_id is not None else None
        self._open = True

    def snapshot(self) -> bytes:
        """Current value of every requested channel, plus missed ring events after Last-Event-ID."""
        hub = self._hub
        with hub._cond:
            frames = [(seq, frame) for ch, (seq, frame, _) in hub._latest.items() if ch in self.channels]
            if self._ring_cursor is not None:
                frames += [(seq, frame) for seq, ch, frame in hub._ring
                           if seq > self._ring_cursor and ch in self.channels]
            self.cursor = hub._seq
        frames.sort()
        return b"".join(frame for _, frame in frames)

    def wait(self, timeout_s: float) -> bytes | None:
        """Frames that changed since the last call, newest value only; b"" on timeout, None once closed."""
        hub = self._hub
        with hub._cond:
            if hub._seq == self.cursor and not hub._closed:
                hub._cond.wait(timeout_s)
            if hub._closed:
                return None
            return self.poll()

    def poll(self) -> bytes:
        """Frames that changed since the last call, without waiting (b"" if nothing changed)."""
        hub = self._hub
        with hub._cond:
            cursor = self.cursor
            if hub._seq == cursor:
                return b""
            seq, channel, frame = hub._last_change
            if seq == cursor + 1:
                # The usual case, one poll per change as it happens: no scan of every channel.
                self.cursor = seq
                return frame if channel in self.channels else b""
            frames = [(seq, frame) for ch, (seq, frame, _) in hub._latest.items()
                      if seq > cursor and ch in self.channels]
            for seq, ch, frame in reversed(hub._ring):
                if seq <= cursor:
                    break
                if ch in self.channels:
                    frames.append((seq, frame))
            self.cursor = hub._seq
        if len(frames) > 1:
            frames.sort()
        return b"".join(frame for _, frame in frames)

    def close(self) -> None:
        if self._open:
            self._open = False
            self._hub._release(self.channels)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
