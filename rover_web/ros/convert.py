"""Messages <-> plain dicts and domain values. Pure functions; the only rclpy-typed code is here."""

from __future__ import annotations

import array
import math
from typing import Any

from .typesupport import message_class


def yaw_from_quaternion(x: float, y: float, z: float, w: float) -> float:
    """Heading about +z (REP 103), in radians in (-pi, pi]."""
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def quaternion_from_yaw(yaw: float) -> tuple[float, float, float, float]:
    half = yaw / 2.0
    return (0.0, 0.0, math.sin(half), math.cos(half))


def stamp_to_float(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def _plain(value: Any, max_items: int | None) -> Any:
    if hasattr(value, "get_fields_and_field_types"):
        return message_to_dict(value, max_items)
    if isinstance(value, float):
        # JSON has no NaN or Infinity; show them as text rather than lose the message.
        return value if math.isfinite(value) else str(value)
    if isinstance(value, bytes) and len(value) == 1:
        return value[0]  # rclpy gives a `byte` (alone or in a byte[]) as a one-byte bytes object
    if isinstance(value, (bytes, bytearray, array.array, list, tuple)) or type(value).__module__ == "numpy":
        if type(value).__module__ == "numpy" and getattr(value, "ndim", 1) == 0:
            return _plain(value.item(), max_items)
        # Cut before converting: an image's data is a million-element array, and turning all of
        # it into Python ints only to keep the first few costs tens of milliseconds per message.
        length = len(value)
        head = value if max_items is None or length <= max_items else value[:max_items]
        if isinstance(head, (bytes, bytearray)):
            items = list(head)
        elif isinstance(head, array.array) or type(head).__module__ == "numpy":
            items = [_plain(v, max_items) for v in head.tolist()]  # floats may be NaN
        else:
            items = [_plain(v, max_items) for v in head]
        if len(head) < length:
            return {"truncated": True, "length": length, "head": items}
        return items
    return value


def message_to_dict(msg: Any, max_items: int | None = None) -> dict[str, Any]:
    """Any message, field by field; arrays longer than max_items become {truncated, length, head}."""
    return {name: _plain(getattr(msg, name), max_items) for name in msg.get_fields_and_field_types()}


def dict_to_message(type_name: str, data: dict[str, Any]) -> Any:
    """Build a message from a dict of its fields (missing fields keep their defaults)."""
    msg = message_class(type_name)()
    _fill(msg, data)
    return msg


def _fill(msg: Any, data: dict[str, Any]) -> None:
    fields = msg.get_fields_and_field_types()
    for name, value in data.items():
        if name not in fields:
            raise ValueError(f"{type(msg).__name__} has no field {name!r}")
        current = getattr(msg, name)
        if isinstance(value, dict) and hasattr(current, "get_fields_and_field_types"):
            _fill(current, value)
        elif isinstance(value, list) and fields[name].startswith("sequence<") and "/" in fields[name]:
            inner = fields[name][len("sequence<"):].split(",")[0].rstrip(">")
            package, _, name_only = inner.partition("/")
            items = []
            for item in value:
                child = message_class(f"{package}/msg/{name_only}")()
                _fill(child, item)
                items.append(child)
            setattr(msg, name, items)
        elif fields[name] in ("byte", "octet") and isinstance(value, int):
            setattr(msg, name, bytes([value]))  # JSON has no bytes; rclpy wants b"\x01" for a ROS byte
        elif fields[name] in ("float", "double") and isinstance(value, int) and not isinstance(value, bool):
            # JSON's 4 is an int: rclpy (field checks off) keeps it and its C side then reads the int
            # object as a double, sending 2e-323 for 4 and NaN for -1
            setattr(msg, name, float(value))
        else:
            setattr(msg, name, value)


def twist_message(linear_x: float, angular_z: float, *, stamped: bool = False, stamp=None,
                  frame_id: str = ""):
    """geometry_msgs/Twist, or TwistStamped with the given stamp; a fresh message every call."""
    if stamped:
        msg = message_class("geometry_msgs/msg/TwistStamped")()
        if stamp is not None:
            msg.header.stamp = stamp
        msg.header.frame_id = frame_id
        twist = msg.twist
    else:
        msg = message_class("geometry_msgs/msg/Twist")()
        twist = msg
    twist.linear.x = float(linear_x)
    twist.angular.z = float(angular_z)
    return msg
