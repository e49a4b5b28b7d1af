"""The /rosout ring: the last N log lines, queried with filters, repeats grouped. Pure Python.

Bounded twice: at most `keep` lines, and at most `max_bytes` of their text (msgs.py cuts each
field on arrival, so one line is at most a few kilobytes), so a node that logs 1,000 long lines a
second costs a fixed amount of memory. Lines received since the last `drain()` wait in a second bounded list for
the `rosout` channel, so the browser gets a few batches a second instead of one event per line.
"""

from __future__ import annotations

import threading
import time
from collections import deque

from rover_web.web.api_messages import explain

LEVELS = {"DEBUG": 10, "INFO": 20, "WARN": 30, "ERROR": 40, "FATAL": 50}
NAMES = {v: k for k, v in LEVELS.items()}
ERROR_WINDOW_S = 60.0
LINE_OVERHEAD_BYTES = 200  # a line's dict, its numbers and keys, besides its text


def line_bytes(line: dict) -> int:
    """What a line costs the ring, roughly: its text and a fixed overhead."""
    return LINE_OVERHEAD_BYTES + sum(len(line[k]) for k in ("msg", "node", "file", "function"))


def level_name(level: int) -> str:
    return NAMES.get(level, str(level))


def parse_level(text: str) -> int:
    """A level by name (case-insensitive, WARNING too) or number; ValueError otherwise."""
    key = text.strip().upper()
    if key == "WARNING":
        key = "WARN"
    if key in LEVELS:
        return LEVELS[key]
    if key.isdigit() and 0 <= int(key) <= 255:
        return int(key)
    raise ValueError(explain("level must be one of %(levels)s or a number 0-255, not %(value)s",
                             levels=", ".join(LEVELS), value=repr(text[:20])))


def same_line(a: dict, b: dict) -> bool:
    return a["level"] == b["level"] and a["node"] == b["node"] and a["msg"] == b["msg"]


class LogRing:
    def __init__(self, keep: int, batch_max: int = 250, clock=time.monotonic, max_bytes: int = 16 << 20):
        self.keep = keep
        self.max_bytes = max_bytes
        self._lines: deque[dict] = deque()
        self._costs: deque[int] = deque()  # line_bytes of each line in _lines
        self.bytes = 0
        self._errors: deque[float] = deque(maxlen=keep)  # receive times of ERROR and FATAL lines
        self._pending: list[dict] = []
        self._batch_max = batch_max
        self._skipped = 0
        self._seq = 0
        self._clock = clock
        self._lock = threading.Lock()

    def add(self, line: dict) -> None:
        """From the ROS callback: O(1), no I/O."""
        with self._lock:
            self._seq += 1
            line["seq"] = self._seq
            cost = line_bytes(line)
            self._lines.append(line)
            self._costs.append(cost)
            self.bytes += cost
            # The newest line always stays, whatever it costs; older ones go until both bounds hold.
            while len(self._lines) > 1 and (len(self._lines) > self.keep or self.bytes > self.max_bytes):
                self._lines.popleft()
                self.bytes -= self._costs.popleft()
            if line["level"] >= LEVELS["ERROR"]:
                self._errors.append(self._clock())
            if len(self._pending) < self._batch_max:
                self._pending.append(line)
            else:
                self._skipped += 1  # the page can read them from GET /api/rosout

    def __len__(self) -> int:
        with self._lock:
            return len(self._lines)

    @property
    def last_seq(self) -> int:
        """The number of the newest line (lines are numbered 1, 2, ... as they arrive)."""
        with self._lock:
            return self._seq

    def drain(self) -> tuple[list[dict], int]:
        """(lines since the last drain, oldest first; how many more came than one batch holds)."""
        with self._lock:
            pending, self._pending = self._pending, []
            skipped, self._skipped = self._skipped, 0
        return pending, skipped

    def errors_last_minute(self, now: float | None = None) -> int:
        now = self._clock() if now is None else now
        with self._lock:
            while self._errors and now - self._errors[0] > ERROR_WINDOW_S:
                self._errors.popleft()
            return len(self._errors)

    def query(self, min_level: int = 0, node: str = "", contains: str = "", limit: int = 200) -> list[dict]:
        """Newest first: lines at or above `min_level`, from a node whose name contains `node`,
        whose text contains `contains` (both case-insensitive); repeats grouped; at most `limit` groups."""
        return self.query_at(min_level, node, contains, limit)[0]

    def query_at(self, min_level: int = 0, node: str = "", contains: str = "",
                 limit: int = 200) -> tuple[list[dict], int]:
        """query(), and the number of the newest line it saw (the page's place in the `rosout` channel)."""
        with self._lock:
            lines, last_seq = list(self._lines), self._seq
        node, contains = node.lower(), contains.lower()
        grouped: list[dict] = []
        for line in reversed(lines):
            if line["level"] < min_level:
                continue
            if node and node not in line["node"].lower():
                continue
            if contains and contains not in line["msg"].lower():
                continue
            if grouped and same_line(grouped[-1], line):
                grouped[-1]["count"] += 1
                grouped[-1]["first_stamp"] = line["stamp"]
                continue
            if len(grouped) >= limit:
                break
            grouped.append({**line, "count": 1, "first_stamp": line["stamp"]})
        return grouped, last_seq
