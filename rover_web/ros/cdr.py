"""The few fields a channel shows, read straight from a message's serialized (CDR) bytes.

Why: rclpy builds every field of a message as Python objects; a nav_msgs/Odometry's two
36-double covariance arrays become numpy arrays the GUI never reads. At 100 Hz /odom that was
half of the event path's cost: a bare rclpy subscriber took 10 % of a core with messages and
5.4 % with raw bytes (BENCHMARKS.md, 2026-11-27). rosbags' pure-Python deserializer builds the
whole message too (66 µs against rclpy's 95 µs); reading five numbers at known offsets takes a
few microseconds. Only plain CDR (XCDR1, either byte order) is read here, which is what ROS 2's
DDS middlewares send; anything else goes through rclpy's own deserializer (`deserialize`).
"""

from __future__ import annotations

import struct
from typing import NamedTuple

from .typesupport import message_class

# The encapsulation header's first two bytes: CDR big endian, CDR little endian.
_BYTE_ORDER = {b"\x00\x00": ">", b"\x00\x01": "<"}
_COVARIANCE = 36 * 8


class NotPlainCdr(ValueError):
    """Bytes this reader does not take (another encapsulation, or cut short)."""


class OdometryFields(NamedTuple):
    sec: int
    nanosec: int
    frame_id: str
    x: float
    y: float
    qx: float
    qy: float
    qz: float
    qw: float
    linear_x: float
    angular_z: float

    @property
    def stamp(self) -> float:
        return self.sec + self.nanosec * 1e-9


def _string(buf: memoryview, offset: int, order: str) -> tuple[str, int]:
    offset = (offset + 3) & ~3
    (length,) = struct.unpack_from(order + "I", buf, offset)
    start, end = offset + 4, offset + 4 + length
    if length == 0 or end > len(buf) or buf[end - 1] != 0:
        raise NotPlainCdr("bad string")
    return bytes(buf[start:end - 1]).decode("utf-8", "replace"), end


def odometry(raw: bytes) -> OdometryFields:
    """nav_msgs/msg/Odometry: the stamp, frame, planar pose and the speeds a person reads."""
    order = _BYTE_ORDER.get(bytes(raw[:2]))
    if order is None:
        raise NotPlainCdr("not plain CDR")
    buf = memoryview(raw)[4:]  # CDR aligns relative to the end of the encapsulation header
    try:
        sec, nanosec = struct.unpack_from(order + "iI", buf, 0)
        frame_id, offset = _string(buf, 8, order)
        _child, offset = _string(buf, offset, order)
        offset = (offset + 7) & ~7
        x, y, _z, qx, qy, qz, qw = struct.unpack_from(order + "7d", buf, offset)
        offset += 7 * 8 + _COVARIANCE
        linear_x, _vy, _vz, _wx, _wy, angular_z = struct.unpack_from(order + "6d", buf, offset)
    except struct.error as exc:
        raise NotPlainCdr(str(exc)) from None
    if offset + 6 * 8 + _COVARIANCE > len(buf):
        raise NotPlainCdr("cut short")
    return OdometryFields(sec, nanosec, frame_id, x, y, qx, qy, qz, qw, linear_x, angular_z)


def deserialize(raw: bytes, msg_type: str):
    """The whole message, by rclpy: for bytes the fast readers above do not take."""
    from rclpy.serialization import deserialize_message

    return deserialize_message(raw, message_class(msg_type))
