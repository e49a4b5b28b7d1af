"""The live map page in Chromium: robot on the canvas, click and drag goals, waypoints, maps, zoom."""

import json
import math
import time
from urllib.parse import quote

import pytest
import requests

from rover_web.livemap.map_files import load_catalog, maps_file_path

pytestmark = pytest.mark.browser

BASEMENT = "Science Hall Basement"
B = quote(BASEMENT)
AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"
GOAL = "geometry_msgs/msg/PoseStamped"
CATALOG = load_catalog(maps_file_path("map_files/all_maps.json"))
ROBOT_RGB = (31, 111, 235)


def amcl(x, y, yaw=0.0):
    return {"header": {"frame_id": "map"},
            "pose": {"pose": {"position": {"x": x, "y": y},
                              "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}}


def yaw_of(msg):
    q = msg["pose"]["orientation"]
    return math.atan2(2 * (q["w"] * q["z"] + q["x"] * q["y"]), 1 - 2 * (q["y"] ** 2 + q["z"] ** 2))


def state(page):
    return page.evaluate("window.liveMapState")


def open_map(page, url, name=B):
    page.goto(f"{url}/livemap/{name}")
    page.wait_for_function("window.liveMapState && window.liveMapState.imageLoaded"
                           " && window.liveMapState.serverState === 'live'", timeout=15000)
    return state(page)


def expected_screen(s, x, y, name=BASEMENT):
    """Where (x, y) in map metres must be on the canvas, from the server's geometry and the page's view."""
    px, py = CATALOG[name].geometry.world_to_pixel(x, y)
    return s["view"]["offsetX"] + px * s["view"]["scale"], s["view"]["offsetY"] + py * s["view"]["scale"]


def canvas_origin(page):
    box = page.locator("#livemap-canvas").bounding_box()
    return box["x"], box["y"]


def canvas_rgb(page, x, y):
    return tuple(page.evaluate("""([x, y]) => {
        const c = document.getElementById('livemap-canvas');
        const dpr = window.devicePixelRatio || 1;
        return Array.from(c.getContext('2d').getImageData(Math.round(x * dpr), Math.round(y * dpr), 1, 1)
            .data.slice(0, 3));
    }""", [x, y]))


def publish_pose_until_shown(page, peer, x, y, yaw=0.0, timeout=15):
    deadline = time.monotonic() + timeout
    while True:
        peer.publish("/amcl_pose", amcl(x, y, yaw))
        try:
            page.wait_for_function(f"window.liveMapState.pose && window.liveMapState.pose.x === {x}"
                                   f" && window.liveMapState.pose.y === {y}", timeout=1000)
            return state(page)
        except Exception:
            if time.monotonic() > deadline:
                raise


@pytest.fixture
def pose_peer(ros_peer):
    peer = ros_peer()
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    return peer


@pytest.fixture
def goal_peer(ros_peer):
    peer = ros_peer("goal_listener")
    peer.subscribe("/goal_pose", GOAL)
    peer.wait_match("/goal_pose")
    return peer


def goal_answered(page, after=None):
    """The answered goal request, waiting in Playwright: its request routing (PageWatch) only runs
    while the test is inside a Playwright call. `after`: an earlier answer, which does not count
    (the page may not have sent the next goal yet when the test starts waiting)."""
    page.wait_for_function(
        """previous => { const g = window.liveMapState.lastGoal;
                         return g && g.status !== 'sending' && JSON.stringify(g.request) !== previous; }""",
        arg=json.dumps(after["request"], separators=(",", ":")) if after else None)
    return state(page)["lastGoal"]


def warm_up_goals(url, peer):
    deadline = time.monotonic() + 10
    while not peer.received("/goal_pose"):
        assert time.monotonic() < deadline
        requests.post(f"{url}/api/maps/{B}/goal", json={"x": 0.0, "y": 0.0}, timeout=5)
        time.sleep(0.1)
    time.sleep(0.2)
    peer.clear("/goal_pose")


@pytest.mark.ros
def test_the_robot_is_drawn_where_the_publisher_put_it(live_server, page, pose_peer):
    open_map(page, live_server.url)
    s = publish_pose_until_shown(page, pose_peer, 23.0, 4.0, math.pi / 2)
    ex, ey = expected_screen(s, 23.0, 4.0)
    assert (s["pose"]["screen"]["x"], s["pose"]["screen"]["y"]) == pytest.approx((ex, ey), abs=0.01)
    assert s["pose"]["pixels"] == {"x": 500.0, "y": 370.0, "yaw": pytest.approx(math.pi / 2, abs=1e-4),
                                   "inside": True}
    assert s["poseState"] == "live" and s["noPose"] is False
    assert page.locator("#livemap-pose-state").inner_text() == "pose live"
    # Track and zoom in so the robot is big, then read the canvas itself.
    page.check("#livemap-track")
    for _ in range(4):
        page.click("#livemap-zoom-in")
    page.wait_for_function("window.liveMapState.view.scale > 2.5 && window.liveMapState.tracking")
    s = state(page)
    ex, ey = expected_screen(s, 23.0, 4.0)
    assert (ex, ey) == pytest.approx((s["canvas"]["width"] / 2, s["canvas"]["height"] / 2), abs=1.0)
    radius = s["pose"]["radius_px"]
    assert radius == pytest.approx(0.177 / 0.05 * s["view"]["scale"], rel=1e-6)   # the real 35.4 cm diameter
    assert canvas_rgb(page, ex + radius * 0.5, ey + radius * 0.3) == ROBOT_RGB      # body, beside the heading line
    assert min(canvas_rgb(page, ex, ey - radius * 0.7)) >= 200                      # white heading line points up (+y)
    assert canvas_rgb(page, ex, ey + radius * 0.7) == ROBOT_RGB                      # and not down
    assert canvas_rgb(page, ex + radius * 1.5, ey) != ROBOT_RGB
    # The robot moves; tracking keeps it in the middle of the view.
    s = publish_pose_until_shown(page, pose_peer, 30.0, 19.0)
    page.wait_for_function("Math.abs(window.liveMapState.pose.screen.x - window.liveMapState.canvas.width / 2) < 1")
    s = state(page)
    assert expected_screen(s, 30.0, 19.0) == pytest.approx((s["canvas"]["width"] / 2, s["canvas"]["height"] / 2),
                                                           abs=1.0)
    assert page.locator("#livemap-robot").inner_text().startswith("30.00, 19.00 m")
    assert page.watch.offhost == [] and page.watch.console_errors == []


@pytest.mark.ros
def test_click_and_drag_on_the_map_send_goals_a_subscriber_receives(live_server, page, goal_peer):
    warm_up_goals(live_server.url, goal_peer)
    s = open_map(page, live_server.url)
    left, top = canvas_origin(page)
    # A plain click in goal mode: the goal is the clicked point.
    page.click("#livemap-goal-mode")
    assert page.locator("#livemap-goal-mode").get_attribute("aria-pressed") == "true"
    x, y = expected_screen(s, 12.0, 10.5)
    page.mouse.click(left + x, top + y)
    first = goal_answered(page)
    msg = goal_peer.wait_for("/goal_pose")["msg"]
    assert msg["header"]["frame_id"] == "map"
    tolerance = 0.05 / s["view"]["scale"] + 0.01   # within a screen pixel
    assert msg["pose"]["position"]["x"] == pytest.approx(12.0, abs=tolerance)
    assert msg["pose"]["position"]["y"] == pytest.approx(10.5, abs=tolerance)
    page.wait_for_function("window.liveMapState.mode === 'pan' && window.liveMapState.goal")
    assert state(page)["lastGoal"]["status"] == 200
    # Press and drag: the goal is where the press was, heading towards the release (up-right = 45 degrees).
    goal_peer.clear("/goal_pose")
    page.click("#livemap-goal-mode")
    x, y = expected_screen(s, 23.0, 10.5)
    page.mouse.move(left + x, top + y)
    page.mouse.down()
    page.mouse.move(left + x + 30, top + y - 30, steps=5)
    page.mouse.move(left + x + 60, top + y - 60, steps=5)
    page.mouse.up()
    assert goal_answered(page, after=first)["request"]["x"] == pytest.approx(23.0, abs=tolerance)
    msg = goal_peer.wait_for("/goal_pose")["msg"]
    assert msg["pose"]["position"]["x"] == pytest.approx(23.0, abs=tolerance)
    assert msg["pose"]["position"]["y"] == pytest.approx(10.5, abs=tolerance)
    assert yaw_of(msg) == pytest.approx(math.pi / 4, abs=0.02)
    page.wait_for_function("window.liveMapState.goal && window.liveMapState.goal.x > 22")
    g = state(page)["goal"]
    assert (g["screen"]["x"], g["screen"]["y"]) == pytest.approx(expected_screen(state(page), g["x"], g["y"]),
                                                                 abs=0.01)
    # A click in pan mode on empty floor sends nothing.
    goal_peer.clear("/goal_pose")
    last = state(page)["lastGoal"]
    page.mouse.click(left + x, top + y)
    page.wait_for_timeout(500)   # not time.sleep: the page's requests must be let through meanwhile
    assert state(page)["lastGoal"] == last
    assert goal_peer.received("/goal_pose") == []
    assert page.watch.offhost == [] and page.watch.console_errors == []


@pytest.mark.ros
def test_waypoints_on_the_canvas_and_in_the_list_are_sent_as_goals(live_server, page, goal_peer):
    warm_up_goals(live_server.url, goal_peer)
    s = open_map(page, live_server.url)
    left, top = canvas_origin(page)
    lab_b12 = next(w for w in CATALOG[BASEMENT].waypoints if w.name == "Lab B12")
    drawn = next(w for w in s["waypoints"] if w["name"] == "Lab B12")
    x, y = expected_screen(s, lab_b12.x, lab_b12.y)
    assert (drawn["screen"]["x"], drawn["screen"]["y"]) == pytest.approx((x, y), abs=0.01)
    page.mouse.click(left + x + 2, top + y - 2)   # near enough the marker
    goal_answered(page)
    msg = goal_peer.wait_for("/goal_pose")["msg"]
    assert (msg["pose"]["position"]["x"], msg["pose"]["position"]["y"]) == (lab_b12.x, lab_b12.y)
    goal_peer.clear("/goal_pose")
    page.get_by_role("button", name="Mail Room").click()
    page.wait_for_function("window.liveMapState.lastGoal.request.x === 4")
    goal_answered(page)
    msg = goal_peer.wait_for("/goal_pose")["msg"]
    assert (msg["pose"]["position"]["x"], msg["pose"]["position"]["y"]) == (4.0, 5.0)
    assert yaw_of(msg) == pytest.approx(-math.pi / 2, abs=1e-5)
    page.wait_for_function("document.getElementById('livemap-message').textContent.includes('Mail Room')")


def test_switching_maps(live_server, page):
    s = open_map(page, live_server.url)
    assert s["map"] == BASEMENT and (s["geometry"]["w"], s["geometry"]["h"]) == (800, 480)
    page.select_option("#livemap-select", "Robotics Lab")
    page.wait_for_url(f"**/livemap/{quote('Robotics Lab')}")
    page.wait_for_function("window.liveMapState && window.liveMapState.map === 'Robotics Lab'"
                           " && window.liveMapState.imageLoaded")
    s = state(page)
    assert (s["geometry"]["w"], s["geometry"]["h"], s["geometry"]["res"]) == (480, 360, 0.025)
    assert page.locator("#livemap-select").input_value() == "Robotics Lab"
    assert [w["name"] for w in s["waypoints"]][:2] == ["Door", "Charger"]
    # The whole map is in view after the switch.
    assert s["view"]["offsetX"] >= 0 and s["view"]["offsetY"] >= 0
    assert s["view"]["offsetX"] + 480 * s["view"]["scale"] <= s["canvas"]["width"] + 0.5
    assert page.watch.console_errors == []


def test_zoom_with_buttons_wheel_and_pinch_and_pan_by_dragging(live_server, browser):
    context = browser.new_context(viewport={"width": 1280, "height": 900}, has_touch=True, bypass_csp=True)
    try:
        page = context.new_page()
        s0 = open_map(page, live_server.url)
        scale0 = s0["view"]["scale"]
        page.click("#livemap-zoom-in")
        page.wait_for_function(f"window.liveMapState.view.scale > {scale0 * 1.2}")
        assert state(page)["view"]["scale"] == pytest.approx(scale0 * 1.25)
        page.click("#livemap-zoom-out")
        page.wait_for_function(f"Math.abs(window.liveMapState.view.scale - {scale0}) < 1e-9")
        # Wheel: zooms in about the cursor, which stays over the same spot of the floorplan.
        left, top = canvas_origin(page)
        x, y = expected_screen(s0, 30.0, 5.0)
        page.mouse.move(left + x, top + y)
        page.mouse.wheel(0, -300)
        page.wait_for_function(f"window.liveMapState.view.scale > {scale0 * 1.3}")
        s = state(page)
        # Within a pixel: the pointer lands on a whole pixel, and where the canvas starts need not
        # (the touch layout's 44 px controls above it, docs/accessibility.md).
        assert expected_screen(s, 30.0, 5.0) == pytest.approx((x, y), abs=1.0)
        # Drag pans by exactly the drag.
        before = state(page)["view"]
        page.mouse.move(left + 400, top + 300)
        page.mouse.down()
        page.mouse.move(left + 450, top + 280, steps=5)
        page.mouse.up()
        after = state(page)["view"]
        assert (after["offsetX"] - before["offsetX"], after["offsetY"] - before["offsetY"]) == pytest.approx((50, -20))
        # Fit shows the whole map again.
        page.click("#livemap-fit")
        page.wait_for_function(f"Math.abs(window.liveMapState.view.scale - {scale0}) < 1e-9")
        # Pinch: two fingers moving apart zoom in about their midpoint.
        cdp = context.new_cdp_session(page)
        cx, cy = left + 500, top + 300

        def touch(kind, spread):
            points = [] if kind == "touchEnd" else [{"x": cx - spread, "y": cy, "id": 0},
                                                    {"x": cx + spread, "y": cy, "id": 1}]
            cdp.send("Input.dispatchTouchEvent", {"type": kind, "touchPoints": points})

        anchor = state(page)
        touch("touchStart", 50)
        for spread in range(55, 101, 5):
            touch("touchMove", spread)
        touch("touchEnd", 0)
        page.wait_for_function(f"window.liveMapState.view.scale > {scale0 * 1.8}")
        s = state(page)
        assert s["view"]["scale"] == pytest.approx(scale0 * 2.0, rel=0.05)
        # The floorplan point that was under the fingers' midpoint is still there.
        px = (cx - left - anchor["view"]["offsetX"]) / anchor["view"]["scale"]
        assert s["view"]["offsetX"] + px * s["view"]["scale"] == pytest.approx(cx - left, abs=1.0)
        assert page.locator("#livemap-scale").inner_text().endswith("cm per pixel")
    finally:
        context.close()


@pytest.mark.ros
def test_no_pose_when_the_pose_is_stale(live_server_factory, page, pose_peer):
    server = live_server_factory(ROVER_WEB_LIVEMAP_POSE_STALE_S=0.5)
    open_map(page, server.url)
    assert page.locator("#livemap-pose-state").inner_text() == "no pose"   # nothing heard yet
    pose_peer.wait_match("/amcl_pose")
    publish_pose_until_shown(page, pose_peer, 2.0, 10.5)
    page.wait_for_function("window.liveMapState.poseState === 'stale'", timeout=5000)
    s = state(page)
    assert s["noPose"] is True and page.locator("#livemap-pose-state").inner_text() == "no pose"
    assert page.locator("#livemap").get_attribute("data-pose-state") == "stale"
    x, y = s["pose"]["screen"]["x"], s["pose"]["screen"]["y"]
    assert canvas_rgb(page, x + s["pose"]["radius_px"] * 0.5, y + 1) != ROBOT_RGB   # drawn grey, not live blue
    publish_pose_until_shown(page, pose_peer, 2.5, 10.5)
    page.wait_for_function("window.liveMapState.poseState === 'live'")


@pytest.mark.ros
def test_dashboard_thumbnail_shows_the_robot_and_links_to_the_map(live_server, page, pose_peer):
    pose_peer.publish("/amcl_pose", amcl(18.0, 10.5))    # the middle of the basement, latched
    page.goto(live_server.url + "/")
    thumb = page.locator("#livemap-thumb")
    assert thumb.get_attribute("href") == f"/livemap/{B}"
    page.wait_for_function("!document.getElementById('livemap-thumb-robot').hidden", timeout=15000)
    # The dot and the thumbnail measured in one go: the dashboard's other cards still move it while
    # they load, and two separate measurements can straddle a move.
    offset = page.evaluate("""() => {
        const d = document.getElementById('livemap-thumb-robot').getBoundingClientRect();
        const b = document.getElementById('livemap-thumb').getBoundingClientRect();
        return [d.x + d.width / 2 - b.x - b.width / 2, d.y + d.height / 2 - b.y - b.height / 2];
    }""")
    assert offset == pytest.approx([0.0, 0.0], abs=1.5)
    page.wait_for_function("document.querySelector('#livemap-thumb img').naturalWidth === 320")
    thumb.click()
    page.wait_for_url(f"**/livemap/{B}")
    page.wait_for_function("window.liveMapState && window.liveMapState.map === 'Science Hall Basement'")
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_the_map_page_fits_a_phone(live_server, browser):
    context = browser.new_context(viewport={"width": 375, "height": 740}, is_mobile=True, has_touch=True,
                                  bypass_csp=True)
    try:
        phone = context.new_page()
        open_map(phone, live_server.url)
        overflow = phone.evaluate("document.documentElement.scrollWidth - document.documentElement.clientWidth")
        assert overflow <= 0, f"page is {overflow}px wider than a phone screen"
        s = state(phone)
        assert s["canvas"]["width"] <= 375 and s["canvas"]["height"] >= 300
    finally:
        context.close()
