"""diagnostic_msgs/msg/DiagnosticArray as plain dicts."""

from __future__ import annotations

DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"
TOPICS = ("/diagnostics", "/diagnostics_agg")


def _level(value) -> int:
    # DiagnosticStatus.level is a ROS `byte`: rclpy hands it over as a one-byte bytes object.
    if isinstance(value, (bytes, bytearray)):
        return value[0] if value else 0
    return int(value)


def statuses(msg) -> list[dict]:
    return [{"name": s.name, "hardware_id": s.hardware_id, "level": _level(s.level), "message": s.message,
             "values": {kv.key: kv.value for kv in s.values}} for s in msg.status]
