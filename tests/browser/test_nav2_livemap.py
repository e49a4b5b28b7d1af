"""Nav2 from LiveMap in Chromium, against the simulator in another process answering as Nav2: a goal
sent by clicking the map, its feedback in the panel, cancel, a route of waypoints, the servers'
lifecycle states; and the panel's message when nav2_msgs is missing."""

import math
import os

import pytest
import requests

from rover_web.config import ROOT
from tests.browser.test_livemap import canvas_origin, expected_screen, open_map, state
from tests.support.waiting import wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def nav2(page) -> dict:
    return page.evaluate("window.nav2State")


def test_a_goal_clicked_on_the_map_goes_to_nav2_shows_feedback_and_is_canceled(live_server, sim_process, page):
    pytest.importorskip("nav2_msgs.action")
    sim_process("--only", "rover")
    wait_until(lambda: requests.get(live_server.url + "/api/nav2", timeout=5).json()["servers"]["to_pose"]["ready"],
               30, "the simulator's NavigateToPose server")
    s = open_map(page, live_server.url)
    page.wait_for_function("window.nav2State && window.nav2State.goal_via === 'action'"
                           " && window.nav2State.lifecycle.every(n => n.state === 'active')", timeout=15000)
    servers = page.locator("#nav2-servers li")
    assert servers.count() == len(nav2(page)["lifecycle"]) >= 5
    assert page.locator("#nav2-servers li[data-node='/bt_navigator'] b").inner_text() == "active"
    assert "NavigateToPose" in page.locator("#nav2-via").inner_text()

    # Set goal, click Lab B12 (around the walls from the Dock)
    page.click("#livemap-goal-mode")
    x, y = expected_screen(s, 23.0, 4.0)
    left, top = canvas_origin(page)
    page.mouse.click(left + x, top + y)
    page.wait_for_function("window.nav2State.lastNav2 && window.nav2State.lastNav2.status === 200", timeout=15000)
    sent = nav2(page)["lastNav2"]
    assert sent["path"] == "/api/nav2/goal"
    goal = sent["reply"]["goal"]
    assert goal["kind"] == "to_pose"
    assert abs(goal["poses"][0]["x"] - 23.0) < 0.1 and abs(goal["poses"][0]["y"] - 4.0) < 0.1

    # Feedback in the panel: distance, time left, time navigating, recoveries
    page.wait_for_function("window.nav2State.feedback && window.nav2State.feedback.navigation_time_s > 1",
                           timeout=15000)
    distance = page.locator("#nav2-distance").inner_text()
    assert distance.endswith(" m") and float(distance[:-2]) > 5
    assert page.locator("#nav2-eta").inner_text() != "—"
    assert page.locator("#nav2-time").inner_text().endswith(" s")
    assert page.locator("#nav2-recoveries").inner_text() == "0"
    assert page.locator("#nav2-status").inner_text() == "executing"
    # the robot moves on the map
    first = state(page)["pose"]
    page.wait_for_function(f"Math.hypot(window.liveMapState.pose.x - {first['x']},"
                           f" window.liveMapState.pose.y - {first['y']}) > 0.3", timeout=15000)

    # Cancel
    assert page.locator("#nav2-cancel").is_enabled()
    page.click("#nav2-cancel")
    page.wait_for_function("window.nav2State.result && window.nav2State.result.status === 'canceled'", timeout=15000)
    assert page.locator("#nav2-result").inner_text().startswith("canceled")
    assert "cancel: operator" in page.locator("#nav2-status").inner_text()
    assert page.locator("#nav2-cancel").is_disabled()


def test_a_route_of_waypoints_is_followed_and_an_unreachable_goal_shows_nav2s_error(live_server, sim_process, page):
    pytest.importorskip("nav2_msgs.action")
    sim_process("--only", "rover", "--goal-speed", "2.0")
    wait_until(lambda: requests.get(live_server.url + "/api/nav2", timeout=5).json()["servers"]["to_pose"]["ready"],
               30, "the simulator's NavigateToPose server")
    s = open_map(page, live_server.url)
    page.wait_for_function("window.nav2State.goal_via === 'action'", timeout=15000)
    waypoints = [w["name"] for w in s["waypoints"]]
    # Mail Room, then a shift-click on the map in Set goal: a route of two
    page.click(f"[data-route-add='{waypoints.index('Mail Room')}']")
    page.click("#livemap-goal-mode")
    x, y = expected_screen(s, 3.0, 10.5)
    left, top = canvas_origin(page)
    page.keyboard.down("Shift")
    page.mouse.click(left + x, top + y)
    page.keyboard.up("Shift")
    route = nav2(page)["route"]
    assert [p["name"] for p in route] == ["Mail Room", ""] and abs(route[1]["x"] - 3.0) < 0.1
    # drawn at the next animation frame, numbered, where the points are
    page.wait_for_function("window.liveMapState.nav2.route.length === 2", timeout=5000)
    drawn = page.evaluate("window.liveMapState.nav2.route")
    assert abs(drawn[1]["screen"]["x"] - x) < 2 and abs(drawn[1]["screen"]["y"] - y) < 2
    assert page.locator("#nav2-route li").count() == 2
    page.select_option("#nav2-route-mode", "follow_waypoints")
    page.click("#nav2-route-send")
    page.wait_for_function("window.nav2State.goal && window.nav2State.goal.kind === 'follow_waypoints'",
                           timeout=15000)
    page.wait_for_function("window.nav2State.feedback && window.nav2State.feedback.current_waypoint === 1",
                           timeout=60000)
    assert page.locator("#nav2-waypoint").inner_text() == "2 of 2"
    page.wait_for_function("window.nav2State.result && window.nav2State.result.status === 'succeeded'",
                           timeout=60000)
    pose = state(page)["pose"]
    assert math.hypot(pose["x"] - 3.0, pose["y"] - 10.5) < 0.15

    # A goal behind walls with no door: aborted, with Nav2's code and message in the panel
    s = state(page)
    assert s["mode"] == "goal"  # a shift-click keeps Set goal on, for the next point of the route
    x, y = expected_screen(s, 37.0, 10.5)
    page.mouse.click(left + x, top + y)
    page.wait_for_function("window.nav2State.result && window.nav2State.result.status === 'aborted'",
                           timeout=30000)
    text = page.locator("#nav2-result").inner_text()
    assert "error 208 NO_VALID_PATH" in text and "no path" in text


def test_without_nav2_msgs_the_panel_says_what_is_missing_and_goals_use_the_topic(server_process, tmp_path,
                                                                                 browser):
    hidden = tmp_path / "hide" / "nav2_msgs"
    hidden.mkdir(parents=True)
    (hidden / "__init__.py").write_text('raise ImportError("nav2_msgs is hidden by this test")\n')
    server = server_process(env={"PYTHONPATH": f"{hidden.parent}{os.pathsep}{ROOT}"}).start()
    api = requests.get(server.url + "/api/nav2", timeout=5).json()
    assert api["available"] is False and api["goal_via"] == "topic"
    assert api["missing"]["packages"] == ["nav2_msgs"]
    message = api["missing"]["message"]
    assert "hidden by this test" in message and "scripts/build_interfaces.sh" in message
    for path, body in (("/api/nav2/goal", {"x": 4.0, "y": 5.0}),
                       ("/api/nav2/route", {"mode": "through_poses", "poses": [{"x": 4.0, "y": 5.0}]}),
                       ("/api/nav2/cancel", {})):
        reply = requests.post(server.url + path, json=body, timeout=5)
        assert reply.status_code == 503, path
        assert reply.json()["error"] == "nav2_unavailable" and "build_interfaces.sh" in reply.json()["message"]
    context = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True)
    try:
        page = context.new_page()
        open_map(page, server.url)
        message = page.locator("#nav2-missing")
        assert message.is_visible()
        assert "nav2_msgs" in message.inner_text() and "build_interfaces.sh" in message.inner_text()
        assert page.locator("#nav2-route-send").is_disabled()
        # A goal still goes, on the goal topic
        page.click("#livemap-goal-mode")
        s = state(page)
        x, y = expected_screen(s, 4.0, 5.0)
        left, top = canvas_origin(page)
        page.mouse.click(left + x, top + y)
        page.wait_for_function("window.liveMapState.lastGoal && window.liveMapState.lastGoal.status === 200",
                               timeout=15000)
        assert page.evaluate("window.liveMapState.lastGoal.reply.topic") == "/goal_pose"
    finally:
        context.close()
