"""rcl_interfaces/msg/Log from /rosout as plain dicts, and the QoS /rosout is published with."""

from __future__ import annotations

from rover_web.ros.convert import stamp_to_float
from rover_web.ros.qos import profile

from .ring import level_name

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


def log_line(msg) -> dict:
    return {
        "stamp": round(stamp_to_float(msg.stamp), 6),
        "level": int(msg.level),
        "level_name": level_name(int(msg.level)),
        "node": msg.name,
        "msg": msg.msg,
        "file": msg.file,
        "function": msg.function,
        "line": int(msg.line),
    }
