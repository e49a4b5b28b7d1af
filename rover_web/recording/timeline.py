"""A recording as a timeline for the replay view: where the robot was, what was logged, who did
what, and what the file holds. Read from the file (whole or cut short) and decoded here, so the
page needs no MCAP or CDR code and nothing is published: a replay in the browser never reaches
the robot.

Bounded whatever the recording's length: decoding costs 0.1-0.3 ms a message in Python, so each
track decodes at most MAX_POINTS of its messages, evenly spread (every k-th, chosen before
decoding), each path at most MAX_PLAN_POINTS points of MAX_PLANS paths, and the logs and the audit
trail at most MAX_LOGS lines each (evenly thinned beyond, and said so). The answer is kept for
the file (timeline_of), so the page's next load costs nothing.
"""

from __future__ import annotations

import json
import math
import threading
from collections import OrderedDict

from rover_web.livemap.msgs import path_points, pose_from_amcl, pose_from_stamped
from rover_web.ros.convert import yaw_from_quaternion

from .bounds import Budget
from .file_index import FileIndex, stride_for

AUDIT_TOPIC = "/rover_web/audit"
MAX_POINTS = 5000
MAX_PLANS = 300
MAX_PLAN_POINTS = 200
MAX_LOGS = 20000
LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}
CACHED = 8


def _fix(msg) -> dict | None:
    if msg.status.status < 0 or not (math.isfinite(msg.latitude) and math.isfinite(msg.longitude)):
        return None  # no fix (as the GPS map reads it: waypoints/gps.py): nothing to draw
    return {"lat": msg.latitude, "lng": msg.longitude}


def _place(x: float, y: float, yaw: float, frame_id: str) -> dict | None:
    if not all(map(math.isfinite, (x, y, yaw))):
        return None  # not a place (and not JSON)
    return {"x": x, "y": y, "yaw": yaw, "frame_id": frame_id}


def _odom(msg) -> dict | None:
    pose = msg.pose.pose
    q = pose.orientation
    return _place(pose.position.x, pose.position.y, yaw_from_quaternion(q.x, q.y, q.z, q.w), msg.header.frame_id)


def _pose(read):
    def convert(msg) -> dict | None:
        x, y, yaw, frame_id, _stamp = read(msg)
        return _place(x, y, yaw, frame_id)
    return convert


def _plan(msg) -> dict:
    frame_id, points, _stamp = path_points(msg)
    points = [p for p in points if math.isfinite(p[0]) and math.isfinite(p[1])]
    return {"frame_id": frame_id, "length": len(points),
            "points": [list(p) for p in _thin(points, MAX_PLAN_POINTS)]}


def _log(msg) -> dict:
    return {"level": LEVELS.get(msg.level, str(msg.level)), "name": msg.name, "msg": msg.msg[:500]}


def _audit(msg) -> dict | None:
    try:
        record = json.loads(msg.data)
    except ValueError:
        return None
    if not isinstance(record, dict):
        return None
    return {"action": str(record.get("action", "")), "by": str(record.get("by", "")),
            "detail": str(record.get("detail", ""))}


# schema name -> (series kind, converter, most messages decoded per topic)
SHOWN = {
    "sensor_msgs/msg/NavSatFix": ("fix", _fix, MAX_POINTS),
    "nav_msgs/msg/Odometry": ("odom", _odom, MAX_POINTS),
    "geometry_msgs/msg/PoseWithCovarianceStamped": ("pose", _pose(pose_from_amcl), MAX_POINTS),
    "geometry_msgs/msg/PoseStamped": ("pose", _pose(pose_from_stamped), MAX_POINTS),
    "nav_msgs/msg/Path": ("plan", _plan, MAX_PLANS),
    "rcl_interfaces/msg/Log": ("logs", _log, MAX_LOGS),
}
SERIES = ("fix", "odom", "pose", "plan")


def timeline(index: FileIndex) -> dict:
    """{"start", "end" (s since the epoch), "complete", "topics": {topic: {type, count, decodable}},
    "series": {"fix"|"odom"|"pose"|"plan": {topic: [...]}}, "thinned": {topic: kept of n},
    "logs": [...], "audit": [...]}; each item has `t`, in time order. NotARecording for a file
    that is not one; bounds.TooCostly for one that costs more than a read may (one budget for all)."""
    budget = index.budget()
    series: dict[str, dict[str, list]] = {kind: {} for kind in SERIES}
    logs: list[dict] = []
    audit: list[dict] = []
    thinned: dict[str, str] = {}
    for topic, info in index.topics().items():
        if topic == AUDIT_TOPIC:
            kind, convert, most = "audit", _audit, MAX_LOGS
        elif info["type"] in SHOWN and info["decodable"]:
            kind, convert, most = SHOWN[info["type"]]
        else:
            continue
        items = decode_sampled(index, topic, convert, most, budget)
        if len(items) < info["count"]:
            thinned[topic] = f"{len(items)} of {info['count']}"
        if kind == "audit":
            audit.extend(items)
        elif kind == "logs":
            logs.extend(items)
        else:
            series[kind][topic] = items
    logs.sort(key=lambda item: item["t"])
    audit.sort(key=lambda item: item["t"])
    return {"start": _seconds(index.start_ns), "end": _seconds(index.end_ns), "complete": index.complete,
            "topics": index.topics(), "series": series, "thinned": thinned, "logs": logs, "audit": audit}


def decode_sampled(index: FileIndex, topic: str, convert, most: int, budget: Budget | None = None) -> list[dict]:
    """convert(decoded) of at most `most` of the topic's messages, every k-th chosen before
    decoding, each with its log time `t` (s), sorted by it; None from convert leaves one out.
    Under `budget` (bounds.py): its time is checked at each message decoded."""
    stride = stride_for(index.count([topic]), most)
    budget = budget or index.budget()
    items = []
    for i, (_channel, message) in enumerate(index.messages([topic], budget=budget)):
        if i % stride:
            continue
        budget.check_time()
        decoded = index.decode(message)
        if decoded is None:
            continue
        try:
            item = convert(decoded)
        except (AttributeError, TypeError, ValueError, IndexError):
            item = None  # a type of that name with other fields (a file from elsewhere)
        if item is not None:
            item["t"] = message.log_time / 1e9
            items.append(item)
    items.sort(key=lambda item: item["t"])
    return items


def _seconds(ns: int | None) -> float | None:
    return None if ns is None else ns / 1e9


def _thin(points: list, most: int) -> list:
    if len(points) <= most:
        return points
    step = len(points) / most
    return [points[int(i * step)] for i in range(most - 1)] + [points[-1]]


_answers: OrderedDict[tuple, dict] = OrderedDict()
_answers_lock = threading.Lock()


def timeline_of(index: FileIndex) -> dict:
    """timeline(index), kept for the last few files (a finished file never changes)."""
    stat = index.path.stat()
    key = (str(index.path), stat.st_size, stat.st_mtime_ns)
    with _answers_lock:
        if key in _answers:
            _answers.move_to_end(key)
            return _answers[key]
    answer = timeline(index)
    with _answers_lock:
        _answers[key] = answer
        while len(_answers) > CACHED:
            _answers.popitem(last=False)
    return answer
