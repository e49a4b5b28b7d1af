"""A replayed recording with /tf and /tf_static places its scans through them: the recorded robot
drives along map +y with its laser upside down and off centre, and the scan replayed from the file
lands on the known wall at the robot's recorded place at the scan's own stamp."""

from __future__ import annotations

import math

import numpy as np
import pytest
from geometry_msgs.msg import TransformStamped
from rclpy.serialization import serialize_message
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from rover_web.recording.recorder import Recorder
from tests.integration.recording.test_replay import ROOMY, replay

pytestmark = pytest.mark.ros

T0 = 1_700_000_000.0
STEP = 0.1


def stamped(t: float):
    from builtin_interfaces.msg import Time

    sec = int(t)
    return Time(sec=sec, nanosec=int(round((t - sec) * 1e9)))


def tf(parent, child, xyz, q, t=0.0) -> TransformStamped:
    m = TransformStamped()
    m.header.stamp = stamped(t)
    m.header.frame_id, m.child_frame_id = parent, child
    m.transform.translation.x, m.transform.translation.y, m.transform.translation.z = map(float, xyz)
    r = m.transform.rotation
    r.x, r.y, r.z, r.w = map(float, q)
    return m


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def recording(path):
    """odom -> base_link x from 3.0 to 4.0 m in 1 s; map -> odom (1, 2) turned 90°: base_link in the map
    at (0, 2 + x) facing 180°. The laser upside down, turned 0.5 rad, at (0.15, -0.08, 0.25) on it."""
    topics = {"/tf": "tf2_msgs/msg/TFMessage", "/tf_static": "tf2_msgs/msg/TFMessage",
              "/scan": "sensor_msgs/msg/LaserScan"}
    rec = Recorder(path, topics, limits=ROOMY, queue_size=1000, metadata={"id": "tf"})
    ns = int(T0 * 1e9)
    flipped = (1.0 * math.cos(0.25), 1.0 * math.sin(0.25), 0.0, 0.0)  # Rz(0.5) Rx(180°)
    rec.offer("/tf_static", serialize_message(TFMessage(transforms=[
        tf("base_link", "flipped", (0.15, -0.08, 0.25), flipped)])), ns)
    for k in range(11):
        t = T0 + k * STEP
        rec.offer("/tf", serialize_message(TFMessage(transforms=[
            tf("map", "odom", (1, 2, 0), yaw_q(math.pi / 2), t),
            tf("odom", "base_link", (3.0 + k * STEP, 1, 0), yaw_q(math.pi / 2), t)])), int(t * 1e9))
        if k == 6:  # the scan measured at 0.55 s, recorded after the transform of 0.6 s (its latency)
            scan = LaserScan()
            scan.header.stamp, scan.header.frame_id = stamped(T0 + 0.55), "flipped"
            scan.angle_min, scan.angle_max, scan.angle_increment = 0.5, 0.6, 0.1
            scan.range_min, scan.range_max = 0.05, 30.0
            scan.ranges = [2.0, 2.0 / abs(math.cos(math.pi + 0.5 - 0.6))]
            rec.offer("/scan", serialize_message(scan), int((t + 0.05) * 1e9))
    rec.stop("requested")
    return path


def test_a_replayed_recording_s_scan_is_placed_through_its_own_tf(live_server, sse_client, tmp_path):
    path = recording(tmp_path / "tf.mcap")
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    done = replay(path, "--delay", "3")
    assert done.returncode == 0, done.stderr
    event = stream.wait_for("scan", lambda d: d["frame_id"] == "flipped", timeout=15)["json"]
    # At 0.55 s odom x is 3.55: base_link at (0, 5.55), the laser at (-0.15, 5.63); beam 0.5 points west
    # (180°) 2 m: the wall at x = -2.15; beam 0.6 at 180° - 0.1 reaches the same wall.
    points = np.array(event["points"]).reshape(-1, 2)
    assert event["placed_by"] == "tf"
    assert points[:, 0] == pytest.approx([-2.15, -2.15], abs=0.01)
    assert points[0, 1] == pytest.approx(5.63, abs=0.01)      # at the scan's stamp, not the newest (6.08)
    assert points[1, 1] == pytest.approx(5.63 + 2.0 * math.tan(0.1), abs=0.01)
