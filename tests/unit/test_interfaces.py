"""The interface packages built from interfaces/ (scripts/build_interfaces.sh) carry the same type
hashes as ROS 2 Jazzy's own: a real robot's /tf and Nav2's action servers match them only if so.

The expected hashes were computed by rosidl from upstream's Jazzy definitions (geometry2's jazzy
branch, navigation2's jazzy branch, Nav2 1.3.13); tf2_msgs/msg/TFMessage's is also the one a Jazzy
robot announces."""

import json
import os
import sys
from pathlib import Path

import pytest

UPSTREAM = {
    ("tf2_msgs", "msg/TFMessage"): "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087",
    ("nav2_msgs", "action/NavigateToPose"):
        "RIHS01_a56dba8a3234a1215e610180dc703ae25bbf406dded8b54887891c9732857eab",
    ("nav2_msgs", "action/NavigateThroughPoses"):
        "RIHS01_4e680a34fd27772095da6ffdb32ae348adbc3d948248d38cf8d5ca3fc7a3a6c4",
    ("nav2_msgs", "action/FollowWaypoints"):
        "RIHS01_09e36a19e0374ab692e78b877e3345daa223ca4186b8af90f77939b78c6e6d7b",
    ("nav2_msgs", "msg/MissedWaypoint"): "RIHS01_cc79d1e3a1b86cd6a80788b16c844c396932462560936293011f062c21b82ed1",
}


@pytest.mark.parametrize(("package", "name"), sorted(UPSTREAM))
def test_type_hash_is_upstreams(package, name):
    # A sourced ROS 2 install names its prefixes; the wheels' venv is its own prefix.
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p] + [sys.prefix]
    path = next(f for p in prefixes if (f := Path(p) / "share" / package / f"{name}.json").is_file())
    described = json.loads(path.read_text())
    hashes = {h["type_name"]: h["hash_string"] for h in described["type_hashes"]}
    assert hashes[f"{package}/{name}"] == UPSTREAM[(package, name)]


def test_messages_import_and_round_trip():
    from geometry_msgs.msg import TransformStamped
    from nav2_msgs.action import FollowWaypoints
    from rclpy.serialization import deserialize_message, serialize_message
    from tf2_msgs.msg import TFMessage

    sent = TFMessage(transforms=[TransformStamped(child_frame_id="laser")])
    sent.transforms[0].header.frame_id = "base_link"
    back = deserialize_message(serialize_message(sent), TFMessage)
    assert (back.transforms[0].header.frame_id, back.transforms[0].child_frame_id) == ("base_link", "laser")
    assert FollowWaypoints.Result.TASK_EXECUTOR_FAILED == 601
