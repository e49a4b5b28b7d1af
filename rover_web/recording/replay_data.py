"""The replay view's other questions of a recording: numeric fields over time (plots), the
diagnostics board at a time, the camera frame at a time. Each reads the file through its chunk
map (file_index.py), decodes with mcap-ros2-support, and reuses the live pages' own code: the
plot page's field paths (plot/field.py), the diagnostics board (diagnostics/board.py) and the
camera's JPEG encoding (camera/imaging.py). Nothing here publishes: the answers go to the page.

Bounds: a series decodes at most SERIES_POINTS messages of its topic (every k-th, chosen before
decoding) for up to MAX_FIELDS fields at once; diagnostics keep at most DIAG_ARRAYS arrays of a
file (evenly thinned beyond), decoded once per file; a frame decompresses the chunks around its
time only, and the last few JPEGs are kept, so a paused or slowly played slider re-encodes nothing.
"""

from __future__ import annotations

import bisect
import math
import threading
from collections import OrderedDict
from dataclasses import dataclass

from rover_web.camera.imaging import Jpeg, encode_frame, error_frame
from rover_web.camera.msgs import COMPRESSED, IMAGE_TYPES, compressed_frame, raw_image
from rover_web.diagnostics.board import DiagnosticsBoard
from rover_web.diagnostics.msgs import DIAGNOSTIC_ARRAY, statuses
from rover_web.plot.field import finite, parse_path, read_number
from rover_web.plot.service import NOT_PLOTTABLE
from rover_web.web.api_messages import explain

from .file_index import FileIndex, stride_for
from .timeline import decode_sampled

MAX_FIELDS = 8
SERIES_POINTS = 5000
FIELDS_LISTED = 400
EXPANDED_ARRAY_MAX = 9  # arrays up to this long are offered element by element, as the plot page does
DIAG_ARRAYS = 5000
CACHED = 16


class NotShown(ValueError):
    """A question this topic cannot answer (wrong type, not decodable); `code` for the 4xx."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


class _Memo:
    """The last few answers, by key (the file's path, size and mtime are part of every key)."""

    def __init__(self, most: int):
        self._most = most
        self._items: OrderedDict = OrderedDict()
        self._lock = threading.Lock()

    def get(self, key, make):
        with self._lock:
            if key in self._items:
                self._items.move_to_end(key)
                return self._items[key]
        value = make()
        with self._lock:
            self._items[key] = value
            while len(self._items) > self._most:
                self._items.popitem(last=False)
        return value


_series = _Memo(CACHED)
_diagnostics = _Memo(4)
_frames = _Memo(CACHED)


def _file_key(index: FileIndex) -> tuple:
    stat = index.path.stat()
    return str(index.path), stat.st_size, stat.st_mtime_ns


def _need(index: FileIndex, topic: str) -> str:
    type_name = index.type_of(topic)
    if type_name is None or not index.count([topic]):
        raise NotShown("unknown_topic", explain("this recording holds no message on %(topic)s",
                                                topic=repr(topic[:120])))
    return type_name


# --- plots ---


def fields(index: FileIndex, topic: str) -> dict:
    """The numeric field paths of the topic's messages, read from its first message."""
    type_name = _need(index, topic)
    if type_name in NOT_PLOTTABLE:
        raise NotShown("not_plottable", explain("%(topic)s is %(type_name)s: bulk data, not numbers to plot",
                                                topic=topic, type_name=type_name))
    sample = None
    for _channel, message in index.messages([topic]):
        sample = index.decode(message)
        break
    if sample is None:
        raise NotShown("not_decodable", explain("%(topic)s's messages cannot be decoded (type %(value)s)",
                                                topic=topic, value=type_name or 'unknown'))
    out: list[str] = []
    _numeric_paths(sample, "", 6, out)
    return {"topic": topic, "type": type_name, "fields": out}


def _numeric_paths(value, prefix: str, depth: int, out: list[str]) -> None:
    if len(out) >= FIELDS_LISTED or depth < 0:
        return
    if isinstance(value, (bool, int, float)):
        out.append(prefix)
    elif isinstance(value, (bytes, bytearray, list, tuple)):
        if not prefix or not len(value):
            return
        for i in range(len(value) if len(value) <= EXPANDED_ARRAY_MAX else 1):
            _numeric_paths(value[i], f"{prefix}[{i}]", depth - 1, out)
    elif hasattr(value, "__slots__"):  # a decoded message (mcap-ros2-support's dynamic classes)
        for name in value.__slots__:
            _numeric_paths(getattr(value, name), f"{prefix}.{name}" if prefix else name, depth - 1, out)


def series(index: FileIndex, topic: str, field_paths: list[str]) -> dict:
    """{"topic", "type", "t": [...], "v": {field: [...]}, "count", "decoded", "skipped_nonfinite"};
    a sample whose value is NaN or infinite is None in its field's list (a gap, as the plot page
    leaves it out). FieldError (plot/field.py) for a malformed path."""
    type_name = _need(index, topic)
    if type_name in NOT_PLOTTABLE:
        raise NotShown("not_plottable", explain("%(topic)s is %(type_name)s: bulk data, not numbers to plot",
                                                topic=topic, type_name=type_name))
    steps = {f: parse_path(f) for f in field_paths}
    return _series.get((_file_key(index), topic, tuple(field_paths)), lambda: _read_series(index, topic, steps))


def _read_series(index: FileIndex, topic: str, steps: dict) -> dict:
    skipped = 0

    def values_of(decoded) -> dict:
        nonlocal skipped
        values = []
        for path in steps.values():
            try:
                value = read_number(decoded, path)
            except (TypeError, ValueError):
                value = None
            if value is not None and not finite(value):
                skipped += 1
                value = None
            values.append(value)
        return {"values": values}

    count = index.count([topic])
    rows = decode_sampled(index, topic, values_of, SERIES_POINTS)
    return {"topic": topic, "type": index.type_of(topic), "t": [row["t"] for row in rows],
            "v": {name: [row["values"][k] for row in rows] for k, name in enumerate(steps)},
            "count": count, "decoded": len(rows), "skipped_nonfinite": skipped}


# --- diagnostics ---


@dataclass
class _DiagnosticsLog:
    times: list[float]
    arrays: list[tuple[str, list[dict]]]  # (topic, statuses), in time order
    first_seen: list[int]  # for each name, the index of the array it first appears in; sorted
    thinned: bool


def _diagnostics_log(index: FileIndex) -> _DiagnosticsLog:
    topics = [t for t, info in index.topics().items() if info["type"] == DIAGNOSTIC_ARRAY]
    stride = stride_for(index.count(topics), DIAG_ARRAYS)
    rows = []
    budget = index.budget()
    for i, (channel, message) in enumerate(index.messages(topics, budget=budget)):
        if i % stride:
            continue
        budget.check_time()
        decoded = index.decode(message)
        if decoded is None:
            continue
        try:
            rows.append((message.log_time / 1e9, channel.topic, statuses(decoded)))
        except (AttributeError, TypeError, ValueError):
            continue  # a DiagnosticArray of another shape
    rows.sort(key=lambda row: row[0])
    seen: dict[str, int] = {}
    for i, (_t, _topic, array) in enumerate(rows):
        for status in array:
            seen.setdefault(status["name"], i)
    return _DiagnosticsLog([r[0] for r in rows], [(r[1], r[2]) for r in rows], sorted(seen.values()), stride > 1)


def diagnostics_at(index: FileIndex, t: float, stale_s: float) -> dict:
    """The diagnostics board as the live page showed it at `t` (s since the epoch): the latest
    status of each name at or before t, its age then, stale past stale_s, the worst per hardware."""
    log = _diagnostics.get(_file_key(index), lambda: _diagnostics_log(index))
    end = bisect.bisect_right(log.times, t)
    names_by_then = bisect.bisect_left(log.first_seen, end)
    latest: dict[str, tuple[float, str, dict]] = {}
    for i in range(end - 1, -1, -1):
        if len(latest) >= names_by_then:
            break
        topic, array = log.arrays[i]
        for status in array:
            latest.setdefault(status["name"], (log.times[i], topic, status))
    now = [t]
    board = DiagnosticsBoard(stale_s, clock=lambda: now[0])
    for received, topic, status in sorted(latest.values(), key=lambda item: item[0]):
        now[0] = received
        board.update([status], topic)
    shown = board.snapshot(now=t)
    return {"t": t, "stale_after_s": stale_s, "statuses": shown, "hardware": DiagnosticsBoard.worst_by_hardware(shown),
            "thinned": log.thinned, "arrays": len(log.times)}


# --- camera ---


def image_topics(index: FileIndex) -> list[str]:
    return [t for t, info in index.topics().items() if info["type"] in IMAGE_TYPES]


def frame_at(index: FileIndex, topic: str, t: float, quality: int, width: int | None,
             height: int | None, max_pixels: int | None = None) -> tuple[Jpeg, float] | None:
    """(the JPEG of the topic's last frame at or before t, its log time), or None before its first
    frame. A frame that cannot be shown is an error frame saying why, as on the live camera."""
    type_name = _need(index, topic)
    if type_name not in IMAGE_TYPES:
        raise NotShown("not_an_image", explain("%(topic)s is %(type_name)s, not sensor_msgs/Image or "
                                               "CompressedImage",
                                               topic=topic, type_name=type_name))
    found = index.latest(topic, int(math.floor(t * 1e9)))
    if found is None:
        return None
    _channel, message = found
    key = (_file_key(index), topic, message.log_time, message.sequence, quality, width, height)
    return _frames.get(key, lambda: (_encode(index, message, type_name, quality, width, height, max_pixels),
                                     message.log_time / 1e9))


def _encode(index: FileIndex, message, type_name: str, quality: int, width, height, max_pixels) -> Jpeg:
    decoded = index.decode(message, most=None)  # one frame, of a type without arrays of messages: bounded
    if decoded is None:
        return error_frame("this frame cannot be decoded", "not_decodable", width, height, 0.0, max_pixels)
    try:
        frame = compressed_frame(decoded) if type_name == COMPRESSED else raw_image(decoded)
    except (AttributeError, TypeError, ValueError):
        return error_frame(f"this {type_name} has other fields", "bad_image", width, height, 0.0, max_pixels)
    return encode_frame(frame, quality, width, height, max_pixels)
