"""A robot placed without AMCL, in Chromium: a SLAM-like peer publishes map -> odom -> base_link on
/tf and no /amcl_pose at all; LiveMap draws the robot where TF puts it, at the right pixels, says
it was placed by TF, and goals still go out."""

import math
import time

import pytest
import requests

from tests.browser.test_livemap import GOAL, ROBOT_RGB, B, canvas_rgb, expected_screen, open_map, state

pytestmark = [pytest.mark.browser, pytest.mark.ros]

TF = "tf2_msgs/msg/TFMessage"


def transform(parent, child, x, y, yaw, t):
    sec = int(t)
    return {"header": {"stamp": {"sec": sec, "nanosec": int((t - sec) * 1e9)}, "frame_id": parent},
            "child_frame_id": child,
            "transform": {"translation": {"x": x, "y": y, "z": 0.0},
                          "rotation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}


def publish_slam(peer, map_odom, odom_base):
    """What SLAM Toolbox and the base's odometry publish: map -> odom and odom -> base_link, now."""
    t = time.time()
    peer.publish("/tf", {"transforms": [transform("map", "odom", *map_odom, t),
                                        transform("odom", "base_link", *odom_base, t)]})


def shown_at(page, peer, map_odom, odom_base, x, y, timeout=15):
    deadline = time.monotonic() + timeout
    while True:
        publish_slam(peer, map_odom, odom_base)
        try:
            page.wait_for_function(f"window.liveMapState.pose && window.liveMapState.pose.x === {x}"
                                   f" && window.liveMapState.pose.y === {y}", timeout=500)
            return state(page)
        except Exception:
            if time.monotonic() > deadline:
                raise


def test_a_slam_robot_with_no_amcl_pose_is_drawn_where_tf_puts_it(live_server, page, ros_peer):
    peer = ros_peer("slam_peer")
    peer.advertise("/tf", TF, qos=100)
    peer.subscribe("/goal_pose", GOAL)
    open_map(page, live_server.url)
    # map -> odom: (20, 7) turned -90°; odom -> base_link: (3, 3) turned +180°. By hand, base_link is
    # at (20, 7) + R(-90°)(3, 3) = (23, 4), facing -90° + 180° = +90° (map +y).
    s = shown_at(page, peer, (20.0, 7.0, -math.pi / 2), (3.0, 3.0, math.pi), 23.0, 4.0)
    assert s["pose"]["pixels"] == {"x": 500.0, "y": 370.0, "yaw": pytest.approx(math.pi / 2, abs=1e-4),
                                   "inside": True}
    ex, ey = expected_screen(s, 23.0, 4.0)
    assert (s["pose"]["screen"]["x"], s["pose"]["screen"]["y"]) == pytest.approx((ex, ey), abs=0.01)
    radius = s["pose"]["radius_px"]
    publish_slam(peer, (20.0, 7.0, -math.pi / 2), (3.0, 3.0, math.pi))
    assert canvas_rgb(page, ex + radius * 0.5, ey + radius * 0.3) == ROBOT_RGB     # the robot's body is drawn there
    assert min(canvas_rgb(page, ex, ey - radius * 0.7)) >= 200                     # its heading line points up (+y)
    page.wait_for_function("document.getElementById('livemap-robot-placed').dataset.placed === 'tf'")
    assert page.locator("#livemap-robot-placed").inner_text() == "Robot: placed by TF"
    # The SLAM correction moves (map -> odom), odometry does not: the robot moves on the map.
    s = shown_at(page, peer, (22.0, 7.0, -math.pi / 2), (3.0, 3.0, math.pi), 25.0, 4.0)
    assert s["pose"]["frame_id"] == "map"
    # A goal still goes out on /goal_pose.
    publish_slam(peer, (22.0, 7.0, -math.pi / 2), (3.0, 3.0, math.pi))
    peer.wait_match("/goal_pose")
    answer = requests.post(f"{live_server.url}/api/maps/{B}/goal", json={"x": 24.0, "y": 5.0}, timeout=5)
    assert answer.status_code == 200, answer.text
    got = peer.wait_for("/goal_pose", lambda m: m["pose"]["position"]["x"] == 24.0)
    assert got["msg"]["header"]["frame_id"] == "map"
    assert page.watch.console_errors == []
