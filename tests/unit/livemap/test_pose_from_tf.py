"""A robot placed without AMCL: LiveMap's pose is TF's map -> base_link, once a tick, only while AMCL
is quiet, and a TF that stops moving goes stale instead of looking fresh."""

import math
import time
import types

import pytest

from rover_web import config
from rover_web.events.hub import EventHub
from rover_web.livemap.service import LiveMapService
from rover_web.tf.buffer import TfBuffer

S = 1_000_000_000


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


@pytest.fixture
def setup():
    buffer = TfBuffer()
    hub = EventHub()
    hub.register("pose", "goal", "plan", "live_map")
    rover = types.SimpleNamespace(config=config.defaults(), hub=hub,
                                  feature=lambda cls: types.SimpleNamespace(buffer=buffer))
    service = LiveMapService(rover, {}, None, None, None)
    yield service, buffer, hub
    hub.close()


def put(buffer, t, odom_x):
    buffer.set_transform("map", "odom", (20.0, 7.0, 0.0), yaw_q(-math.pi / 2), t * S, static=False)
    buffer.set_transform("odom", "base_link", (odom_x, 3.0, 0.0), yaw_q(math.pi), t * S, static=False)


def test_the_pose_is_map_to_base_link_and_a_silent_tf_is_not_taken_again(setup):
    service, buffer, hub = setup
    assert service.placer.buffer is buffer
    service.pose_from_tf()
    assert service.track.pose()[0] is None and hub.latest("pose") is None  # no tree yet: no pose
    put(buffer, 5, 3.0)
    service.pose_from_tf()
    pose = service.track.pose()[0]
    # (20, 7) + R(-90°)(3, 3) = (23, 4), facing -90° + 180° = 90°.
    assert (pose.x, pose.y, pose.yaw) == pytest.approx((23.0, 4.0, math.pi / 2))
    assert pose.frame_id == "map" and pose.stamp_s == 5.0
    assert hub.latest("pose")["placed_by"] == "tf" and service.pose_placed_by == "tf"
    time.sleep(0.05)
    service.pose_from_tf()                      # nothing new on TF: the pose keeps ageing
    assert service.track.pose()[1] >= 0.05
    put(buffer, 6, 4.0)
    service.pose_from_tf()
    assert service.track.pose()[0].y == pytest.approx(3.0) and service.track.pose()[1] < 0.05


def test_amcl_s_pose_wins_while_amcl_speaks(setup):
    service, buffer, hub = setup
    put(buffer, 5, 3.0)
    service.on_pose((1.0, 2.0, 0.0, "map", 5.0))
    service.pose_from_tf()
    assert (service.track.pose()[0].x, service.pose_placed_by) == (1.0, "amcl")
    assert hub.latest("pose")["placed_by"] == "amcl"
