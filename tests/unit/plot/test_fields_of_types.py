"""Which fields of a real message type are numbers (the installed ROS message classes)."""

import pytest

from rover_web.plot.field import FieldError, parse_path
from rover_web.plot.msgs import numeric_kind, numeric_paths

ODOM = "nav_msgs/msg/Odometry"


@pytest.mark.parametrize("path,kind", [("twist.twist.linear.x", "double"), ("pose.covariance[35]", "double"),
                                       ("header.stamp.sec", "int32")])
def test_numeric_fields(path, kind):
    assert numeric_kind(ODOM, parse_path(path)) == kind


def test_sequences_take_any_index_and_bools_count():
    assert numeric_kind("sensor_msgs/msg/JointState", parse_path("position[7]")) == "double"
    assert numeric_kind("std_msgs/msg/Bool", parse_path("data")) == "boolean"


@pytest.mark.parametrize("path,code", [("header.frame_id", "not_numeric"), ("pose.covariance", "not_numeric"),
                                       ("pose.covariance[36]", "no_such_field"), ("twist.nope", "no_such_field"),
                                       ("twist", "not_numeric"), ("twist[0]", "not_array")])
def test_fields_that_are_not_numbers_are_refused_with_a_reason(path, code):
    with pytest.raises(FieldError) as err:
        numeric_kind(ODOM, parse_path(path))
    assert err.value.code == code


def test_the_page_is_offered_the_numeric_paths():
    paths = numeric_paths(ODOM)
    assert "twist.twist.linear.x" in paths and "pose.covariance[0]" in paths
    assert "header.frame_id" not in paths
    assert numeric_paths("sensor_msgs/msg/NavSatFix")[:1] == ["header.stamp.sec"]
