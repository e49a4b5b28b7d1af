"""A recording as a timeline for the replay view: where the robot was, what was logged, who did
what. Read from the file (whole or cut short) and decoded here, so the page needs no MCAP or CDR
code and nothing is published: a replay in the browser never reaches the robot.

Only the types the view shows are decoded (NavSatFix, Odometry, rosout's Log, the audit trail);
each series is thinned evenly to at most MAX_POINTS so a long recording stays a small answer.
"""

from __future__ import annotations

import json
from pathlib import Path

from mcap_ros2.decoder import DecoderFactory

from .reading import Outcome, read_messages

AUDIT_TOPIC = "/rover_web/audit"
MAX_POINTS = 5000
MAX_LOGS = 5000
LEVELS = {10: "DEBUG", 20: "INFO", 30: "WARN", 40: "ERROR", 50: "FATAL"}


def _fix(msg) -> dict | None:
    if msg.status.status < 0:  # no fix: nothing to draw
        return None
    return {"lat": msg.latitude, "lng": msg.longitude}


def _odom(msg) -> dict:
    p = msg.pose.pose.position
    return {"x": p.x, "y": p.y}


def _log(msg) -> dict:
    return {"level": LEVELS.get(msg.level, str(msg.level)), "name": msg.name, "msg": msg.msg[:500]}


def _audit(msg) -> dict | None:
    try:
        record = json.loads(msg.data)
    except ValueError:
        return None
    return {"action": record.get("action", ""), "by": record.get("by", ""), "detail": record.get("detail", "")}


SHOWN = {"sensor_msgs/msg/NavSatFix": ("fix", _fix), "nav_msgs/msg/Odometry": ("odom", _odom),
         "rcl_interfaces/msg/Log": ("logs", _log)}


def timeline(path: Path) -> dict:
    """{"start", "end" (s since the epoch), "complete", "series": {"fix"|"odom": {topic: [...]}},
    "logs": [...], "audit": [...]}; each item has `t`. NotARecording for a file that is not one."""
    decoders = DecoderFactory()
    outcome = Outcome()
    series: dict[str, dict[str, list]] = {"fix": {}, "odom": {}}
    logs: list[dict] = []
    audit: list[dict] = []
    start = end = None
    decode_for: dict[int, object] = {}
    for schema, channel, message in read_messages(path, outcome):
        t = message.log_time / 1e9
        start = t if start is None else min(start, t)
        end = t if end is None else max(end, t)
        if channel.topic == AUDIT_TOPIC:
            kind, convert = "audit", _audit
        elif schema is not None and schema.name in SHOWN:
            kind, convert = SHOWN[schema.name]
        else:
            continue
        decode = decode_for.get(channel.id)
        if decode is None:
            decode = decode_for[channel.id] = decoders.decoder_for(channel.message_encoding, schema)
        item = convert(decode(message.data))
        if item is None:
            continue
        item["t"] = t
        if kind == "audit":
            audit.append(item)
        elif kind == "logs":
            logs.append(item)
        else:
            series[kind].setdefault(channel.topic, []).append(item)
    return {"start": start, "end": end, "complete": outcome.complete,
            "series": {kind: {topic: _thin(points, MAX_POINTS) for topic, points in by_topic.items()}
                       for kind, by_topic in series.items()},
            "logs": logs[-MAX_LOGS:], "audit": audit[-MAX_LOGS:]}


def _thin(points: list, most: int) -> list:
    if len(points) <= most:
        return points
    step = len(points) / most
    return [points[int(i * step)] for i in range(most - 1)] + [points[-1]]
