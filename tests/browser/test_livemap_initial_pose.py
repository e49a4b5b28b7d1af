"""Set pose on the live map in Chromium: the drag a user draws is the pose a real subscriber hears."""

import json
import math

import pytest
import requests

from tests.browser.test_livemap import (
    AMCL,
    canvas_origin,
    canvas_rgb,
    expected_screen,
    open_map,
    publish_pose_until_shown,
    state,
)

pytestmark = [pytest.mark.browser, pytest.mark.ros]

POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
PREVIEW_RGB = (0x56, 0xd4, 0xdd)


def yaw_of(msg):
    q = msg["pose"]["pose"]["orientation"]
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))


def pose_answered(page, after=None):
    page.wait_for_function(
        """previous => { const p = window.liveMapState.lastInitialPose;
                         return p && p.status !== 'sending' && JSON.stringify(p.request) !== previous; }""",
        arg=json.dumps(after["request"], separators=(",", ":")) if after else None)
    return state(page)["lastInitialPose"]


@pytest.fixture
def pose_listener(ros_peer):
    peer = ros_peer("initialpose_listener")
    peer.subscribe("/initialpose", POSE)
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    peer.wait_match("/initialpose")
    return peer


def test_dragging_in_pose_mode_publishes_the_pose_drawn(live_server, page, pose_listener):
    s = open_map(page, live_server.url)
    left, top = canvas_origin(page)
    page.click("#livemap-pose-mode")
    assert page.locator("#livemap-pose-mode").get_attribute("aria-pressed") == "true"
    page.wait_for_function("window.liveMapState.mode === 'pose'")  # the state is published with the next frame
    # Press at (12, 10.5) m and drag straight down the screen: the robot faces -y (-90 degrees).
    x, y = expected_screen(s, 12.0, 10.5)
    page.mouse.move(left + x, top + y)
    page.mouse.down()
    page.mouse.move(left + x, top + y + 40, steps=4)
    page.mouse.move(left + x, top + y + 80, steps=4)
    page.wait_for_function("window.liveMapState.drawCount > 0")
    page.wait_for_timeout(100)  # one animation frame for the preview
    assert canvas_rgb(page, x, y + 40) == PREVIEW_RGB  # the arrow being drawn, in the pose tool's colour
    page.mouse.up()
    answer = pose_answered(page)
    assert answer["status"] == 200
    msg = pose_listener.wait_for("/initialpose")["msg"]
    tolerance = 0.05 / s["view"]["scale"] + 0.01  # within a screen pixel
    assert msg["header"]["frame_id"] == "map"
    assert msg["pose"]["pose"]["position"]["x"] == pytest.approx(12.0, abs=tolerance)
    assert msg["pose"]["pose"]["position"]["y"] == pytest.approx(10.5, abs=tolerance)
    assert yaw_of(msg) == pytest.approx(-math.pi / 2, abs=0.02)
    assert msg["pose"]["covariance"][0] == 0.25
    page.wait_for_function("window.liveMapState.mode === 'pan'")  # one pose, then back to panning
    assert "Initial pose sent on /initialpose" in page.locator("#livemap-message").inner_text()

    # A click without a drag keeps the heading the robot believes it has.
    publish_pose_until_shown(page, pose_listener, 20.0, 5.0, 2.0)
    pose_listener.clear("/initialpose")
    page.locator("#livemap-canvas").focus()
    page.keyboard.press("p")
    page.wait_for_function("window.liveMapState.mode === 'pose'")
    x, y = expected_screen(state(page), 25.0, 6.0)
    page.mouse.click(left + x, top + y)
    pose_answered(page, after=answer)
    msg = pose_listener.wait_for("/initialpose")["msg"]
    assert msg["pose"]["pose"]["position"]["x"] == pytest.approx(25.0, abs=tolerance)
    assert yaw_of(msg) == pytest.approx(2.0, abs=1e-6)
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_an_engaged_estop_refuses_the_pose_and_the_page_says_so(live_server, page, pose_listener):
    s = open_map(page, live_server.url)
    assert requests.post(live_server.url + "/api/estop", json={"engaged": True}, timeout=5).status_code == 200
    left, top = canvas_origin(page)
    page.click("#livemap-pose-mode")
    x, y = expected_screen(s, 12.0, 10.5)
    page.mouse.click(left + x, top + y)
    answer = pose_answered(page)
    assert answer["status"] == 409 and answer["reply"]["error"] == "estop_engaged"
    assert "Initial pose refused" in page.locator("#livemap-message").inner_text()
    page.wait_for_timeout(300)
    assert pose_listener.received("/initialpose") == []
    assert page.watch.offhost == []
