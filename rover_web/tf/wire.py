"""tf2_msgs/msg/TFMessage read straight from its serialized (CDR) bytes, with no message class.

Why: TF is the busiest topic a GUI reads (1,000 transforms a second on a 200-frame robot), and
rclpy builds every TransformStamped as nested Python objects; reading the fields at their offsets
is what rover_web/ros/cdr.py does for /odom. It also needs no tf2_msgs package, which the replay of
a recording (rover_web/tf/replay.py) can do without. Only plain CDR (XCDR1, either byte order) is
read, which is what ROS 2's DDS middlewares and rosbag2 write; anything else raises NotPlainCdr.
"""

from __future__ import annotations

import struct
from typing import NamedTuple

_BYTE_ORDER = {b"\x00\x00": ">", b"\x00\x01": "<"}


class NotPlainCdr(ValueError):
    """Bytes this reader does not take (another encapsulation, or cut short)."""


class Stamped(NamedTuple):
    parent: str
    child: str
    stamp_ns: int
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]


def tf_message(raw: bytes) -> list[Stamped]:
    order = _BYTE_ORDER.get(bytes(raw[:2]))
    if order is None:
        raise NotPlainCdr("not plain CDR")
    buf = memoryview(raw)[4:]  # CDR aligns relative to the end of the encapsulation header
    size = len(buf)
    head = struct.Struct(order + "iiI")   # sequence length... then per item: sec, nanosec, string length
    u32 = struct.Struct(order + "I")
    seven = struct.Struct(order + "7d")
    out = []
    try:
        (count,) = u32.unpack_from(buf, 0)
        if count > size // 64:  # each transform takes at least 64 bytes: a corrupt length, not a huge message
            raise NotPlainCdr("bad sequence length")
        offset = 4
        for _ in range(count):
            sec, nanosec, length = head.unpack_from(buf, offset)
            start = offset + 12
            end = start + length
            if length == 0 or end > size or buf[end - 1] != 0:
                raise NotPlainCdr("bad frame_id")
            parent = bytes(buf[start:end - 1]).decode("utf-8", "replace")
            offset = (end + 3) & ~3
            (length,) = u32.unpack_from(buf, offset)
            start = offset + 4
            end = start + length
            if length == 0 or end > size or buf[end - 1] != 0:
                raise NotPlainCdr("bad child_frame_id")
            child = bytes(buf[start:end - 1]).decode("utf-8", "replace")
            offset = (end + 7) & ~7
            tx, ty, tz, qx, qy, qz, qw = seven.unpack_from(buf, offset)
            offset += 56
            out.append(Stamped(parent, child, sec * 1_000_000_000 + nanosec, (tx, ty, tz), (qx, qy, qz, qw)))
    except struct.error as exc:
        raise NotPlainCdr(str(exc)) from None
    return out
