"""The fuzz's topic watch hears a non-finite float that a node it watches publishes, and only those nodes."""

import math

import pytest

from tests.support.finite_watch import FiniteWatch
from tests.support.rospeer import RosPeer

pytestmark = pytest.mark.ros


def test_the_watch_reports_a_nan_and_an_infinity_in_any_field():
    watched = RosPeer("rover_web_probe")
    other = RosPeer("someone_else")
    watch = FiniteWatch("rover_web")
    try:
        watched.advertise("/probe_twist", "geometry_msgs/msg/Twist")
        watched.advertise("/probe_pose", "geometry_msgs/msg/PoseWithCovariance")
        other.advertise("/other_twist", "geometry_msgs/msg/Twist")
        watch.wait_watching("/probe_twist", "/probe_pose")
        watched.wait_match("/probe_twist")
        watched.wait_match("/probe_pose")
        other.publish("/other_twist", {"linear": {"x": math.nan}})
        watched.publish("/probe_twist", {"linear": {"x": 0.5}})
        watched.publish("/probe_pose", {"covariance": [0.0] * 35 + [math.inf]})
        watched.publish("/probe_twist", {"linear": {"x": 1.0}, "angular": {"z": math.nan}})
        watch.wait_nonfinite(2)
    finally:
        report = watch.finish()
        watched.close()
        other.close()
    assert "/other_twist" not in watch.topics
    assert sorted(report["nonfinite"]) == ["/probe_pose .covariance[35]=inf", "/probe_twist .angular.z=nan"]
    assert report["counts"] == {"/probe_twist": 2, "/probe_pose": 1}
