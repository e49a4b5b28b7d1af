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


SCAN_RGB = (255, 59, 48)


def test_a_scan_through_tf_shows_its_nearest_returns_filled_and_a_far_one_hollow(live_server, page, ros_peer):
    peer = ros_peer("scan_tf_peer")
    peer.advertise("/tf", TF, qos=100)
    peer.advertise("/tf_static", TF, qos="latched")
    peer.advertise("/scan", "sensor_msgs/msg/LaserScan", qos="sensor_data")
    # The laser 0.5 m ahead of base_link; base_link at (22.5, 8) facing +x: the laser at (23, 8).
    peer.publish("/tf_static", {"transforms": [transform("base_link", "lidar", 0.5, 0.0, 0.0, 0.0)]})
    open_map(page, live_server.url)
    ranges = [float("inf")] * 720          # two beams a bin (360 bins): the bin ahead holds 2 m and 5 m
    ranges[360], ranges[361] = 2.0, 5.0

    deadline = time.monotonic() + 20
    while True:
        t = time.time()
        peer.publish("/tf", {"transforms": [transform("map", "odom", 20.0, 8.0, 0.0, t),
                                            transform("odom", "base_link", 2.5, 0.0, 0.0, t)]})
        sec = int(t - 0.01)
        peer.publish("/scan", {"header": {"frame_id": "lidar", "stamp": {"sec": sec, "nanosec": 0}},
                               "angle_min": -math.pi, "angle_max": math.pi - math.pi / 360,
                               "angle_increment": math.pi / 360, "range_min": 0.05, "range_max": 30.0,
                               "ranges": ranges})
        try:
            page.wait_for_function("(() => { const l = window.liveMapState.layers;"
                                   " return l && l.scan && l.scan.far === 1 && l.scan.placed_by === 'tf'; })()",
                                   timeout=1000)
            break
        except Exception:
            if time.monotonic() > deadline:
                raise
    page.wait_for_timeout(200)
    s = state(page)
    assert s["layers"]["scan"]["points"] == 1
    near = expected_screen(s, 25.0, 8.0)
    far = expected_screen(s, 28.0, 8.0)
    assert canvas_rgb(page, near[0], near[1]) == SCAN_RGB            # the nearest: a filled dot
    ring = page.evaluate("""([x, y]) => {
        const c = document.getElementById('livemap-canvas');
        const dpr = window.devicePixelRatio || 1;
        const d = c.getContext('2d').getImageData(Math.round((x - 4) * dpr), Math.round((y - 4) * dpr), 9, 9).data;
        let red = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] > 200 && d[i + 1] < 120 && d[i + 2] < 120) red += 1;
        return red;
    }""", list(far))
    assert ring >= 8                                                 # the farthest: an outline around it
    assert canvas_rgb(page, far[0], far[1]) != SCAN_RGB              # hollow
    assert page.locator("#overlay-placed-scan").inner_text() == "placed by TF"
