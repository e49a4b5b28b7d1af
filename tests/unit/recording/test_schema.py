"""The ros2msg schema text is rosbag2's: root .msg text, then each dependency once, depth first in
sorted order, after 80 '=' and `MSG: <name as written>`."""

import sys
from pathlib import Path

import pytest

from rover_web.recording.schema import SEPARATOR, SchemaNotFound, schema_text


def msg(package: str, name: str) -> str:
    return (Path(sys.prefix) / "share" / package / "msg" / f"{name}.msg").read_text()


def test_a_stamped_type_is_its_text_then_each_dependency_once():
    assert schema_text("std_msgs/msg/Header") == \
        msg("std_msgs", "Header") + f"\n{SEPARATOR}\nMSG: builtin_interfaces/Time\n" + msg("builtin_interfaces", "Time")
    assert schema_text("std_msgs/Header") == schema_text("std_msgs/msg/Header")


def test_dependencies_come_depth_first_in_sorted_order_each_once():
    text = schema_text("nav_msgs/msg/Odometry")
    assert text.startswith(msg("nav_msgs", "Odometry"))
    headers = [line for line in text.splitlines() if line.startswith("MSG: ")]
    assert headers == ["MSG: geometry_msgs/PoseWithCovariance", "MSG: geometry_msgs/Pose", "MSG: geometry_msgs/Point",
                       "MSG: geometry_msgs/Quaternion", "MSG: geometry_msgs/TwistWithCovariance",
                       "MSG: geometry_msgs/Twist", "MSG: geometry_msgs/Vector3", "MSG: std_msgs/Header",
                       "MSG: builtin_interfaces/Time"]
    assert text.count(SEPARATOR) == len(headers)


def test_a_definition_the_decoders_parse():
    from mcap_ros2._dynamic import generate_dynamic

    decoders = generate_dynamic("sensor_msgs/msg/Image", schema_text("sensor_msgs/msg/Image"))
    assert "sensor_msgs/msg/Image" in decoders


@pytest.mark.parametrize("name", ["nope_msgs/msg/Thing", "std_msgs/msg/NoSuch", "not a type"])
def test_a_missing_definition_is_refused_by_name(name):
    with pytest.raises(SchemaNotFound):
        schema_text(name)
