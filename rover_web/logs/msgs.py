"""rcl_interfaces/msg/Log from /rosout as plain dicts, and the QoS /rosout is published with."""

from __future__ import annotations

from rover_web.ros.convert import stamp_to_float
from rover_web.ros.qos import profile

from .ring import level_name

# Fields are cut on arrival (issue 27: 5,000 one-megabyte lines were 5 GB): a line's text keeps its
# first MAX_MSG_CHARS characters, the node, file and function names their first MAX_NAME_CHARS.
MAX_MSG_CHARS = 4000
MAX_NAME_CHARS = 256

LOG = "rcl_interfaces/msg/Log"
ROSOUT = "/rosout"


def rosout_qos():
    """rcl's /rosout publisher in Jazzy: reliable, transient local, keep last 1000 (lifespan 10 s).

    A transient-local subscription also gets what nodes logged just before the app started, and
    it stays compatible with every publisher (a volatile one included).
    """
    qos = profile("latched")
    qos.depth = 1000
    return qos


def cut(text: str, limit: int) -> str:
    """`text`, or its first `limit` characters and a note of how many more there were."""
    if len(text) <= limit:
        return text
    return f"{text[:limit]}… [{len(text) - limit} more characters cut]"


def log_line(msg) -> dict:
    return {
        "stamp": round(stamp_to_float(msg.stamp), 6),
        "level": int(msg.level),
        "level_name": level_name(int(msg.level)),
        "node": cut(msg.name, MAX_NAME_CHARS),
        "msg": cut(msg.msg, MAX_MSG_CHARS),
        "file": cut(msg.file, MAX_NAME_CHARS),
        "function": cut(msg.function, MAX_NAME_CHARS),
        "line": int(msg.line),
    }
