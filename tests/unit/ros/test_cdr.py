"""The Odometry reader against rclpy's and rosbags' own serializers (two independent encoders)."""

from __future__ import annotations

import math

import pytest
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosbags.typesys import Stores, get_typestore

from rover_web.ros import cdr
from rover_web.telemetry import msgs

TYPESTORE = get_typestore(Stores.ROS2_JAZZY)


def odometry(frame_id: str, child: str, i: int) -> Odometry:
    m = Odometry()
    m.header.frame_id, m.child_frame_id = frame_id, child
    m.header.stamp.sec, m.header.stamp.nanosec = 1_764_000_000 + i, 123_456_789
    m.pose.pose.position.x, m.pose.pose.position.y, m.pose.pose.position.z = 1.5 + i, -2.25, 9.0
    m.pose.pose.orientation.z, m.pose.pose.orientation.w = math.sin(0.3), math.cos(0.3)
    m.pose.covariance = [float(k) for k in range(36)]
    m.twist.twist.linear.x, m.twist.twist.linear.y = 0.75, 5.0
    m.twist.twist.angular.x, m.twist.twist.angular.z = 7.0, -0.4
    m.twist.covariance = [-float(k) for k in range(36)]
    return m


# Every string length modulo 4 and 8 for both strings, so each alignment after them is crossed.
@pytest.mark.parametrize("frame_id", ["", "o", "od", "odo", "odom", "odom_", "map/odom", "Ödöm"])
@pytest.mark.parametrize("child", ["", "b", "base", "base_lin", "base_link"])
def test_the_fields_read_equal_rclpys_full_message(frame_id, child):
    m = odometry(frame_id, child, len(frame_id) + len(child))
    raw = serialize_message(m)
    assert msgs.odom_summary_cdr(raw) == msgs.odom_summary(m)
    f = cdr.odometry(raw)
    assert (f.sec, f.nanosec, f.frame_id, f.x, f.y, f.linear_x, f.angular_z) == (
        m.header.stamp.sec, 123_456_789, frame_id, m.pose.pose.position.x, -2.25, 0.75, -0.4)


def test_big_endian_cdr_from_another_encoder_reads_the_same():
    ros = TYPESTORE.types["nav_msgs/msg/Odometry"]
    m = odometry("odom", "base_link", 3)
    as_rosbags = TYPESTORE.deserialize_cdr(serialize_message(m), "nav_msgs/msg/Odometry")
    big = TYPESTORE.serialize_cdr(as_rosbags, "nav_msgs/msg/Odometry", little_endian=False)
    assert big[:2] == b"\x00\x00" and isinstance(as_rosbags, ros)
    assert msgs.odom_summary_cdr(bytes(big)) == msgs.odom_summary(m)


def test_bytes_cut_short_or_of_another_encapsulation_are_refused():
    raw = serialize_message(odometry("odom", "base_link", 0))
    for cut in (0, 3, 4, 12, 30, len(raw) - 1):
        with pytest.raises(cdr.NotPlainCdr):
            cdr.odometry(raw[:cut])
    with pytest.raises(cdr.NotPlainCdr):
        cdr.odometry(b"\x00\x07" + raw[2:])  # XCDR2, little endian


def test_a_string_without_its_terminator_is_refused():
    raw = bytearray(serialize_message(odometry("odom", "base_link", 0)))
    raw[4 + 8 + 4 + 4] = ord("x")  # the NUL after "odom"
    with pytest.raises(cdr.NotPlainCdr):
        cdr.odometry(bytes(raw))
