"""Several robots in a real Chromium: the robot selector, "Stop all", the fleet page and its map,
and the dashboard's battery, against a ROS peer in another process on /boat/... and /drone/...

The server's deadman is 5 s, as in test_teleop.py: every zero seen within a moment of releasing
the stick was sent by the page, not the server's timeout.
"""

import pytest
import requests

from tests.browser.test_teleop import press_stick
from tests.browser.test_waypoints_map import wait_until
from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser

ROBOTS = [{"name": "boat"}, {"name": "drone"}]
NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"
BATTERY_STATE = "sensor_msgs/msg/BatteryState"
BOAT_AT = (-82.4512, 27.3741)   # lng, lat
DRONE_AT = (-82.4490, 27.3762)


@pytest.fixture
def fleet(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_TELEOP_DEADMAN_S=5.0)
    peer = ros_peer("fleet_peer")
    for name in ("boat", "drone"):
        subscribe_cmd_vel(peer, topic=f"/{name}/cmd_vel")
        warm_up(peer, f"{server.url}/robots/{name}", topic=f"/{name}/cmd_vel")
    return server, peer


def robot_url(server, name, path="/"):
    return f"{server.url}/robots/{name}{path}"


def open_live(page, url, drive=True):
    page.goto(url)
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    if drive:
        page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)


def shown_robot(page):
    """The robot the page says it drives: the selector's choice and the title's first word."""
    chosen = page.locator("#robot-select").evaluate("s => s.selectedOptions[0].dataset.robot")
    return chosen, page.title().split(" · ")[0]


def topbar_rows(page):
    """The top bar's height and how many rows its items take (1 when nothing wrapped)."""
    return page.locator(".topbar").evaluate("""bar => {
        const tops = [...bar.children].filter(c => c.getClientRects().length && c.tagName !== 'SCRIPT')
            .map(c => { const r = c.getBoundingClientRect(); return Math.round(r.top + r.height / 2); });
        tops.sort((a, b) => a - b);
        const rows = 1 + tops.slice(1).filter((t, i) => t - tops[i] > 8).length;
        return { height: bar.getBoundingClientRect().height, rows };
    }""")


def drive_once(page, peer, name):
    """Stick up, motion on /<name>/cmd_vel, release, zero."""
    topic = f"/{name}/cmd_vel"
    press_stick(page)
    peer.wait_for(topic, lambda m: m["linear"]["x"] > 0, timeout=5.0)
    page.mouse.up()
    peer.wait_for(topic, is_zero, timeout=2.0)


def test_selector_switches_robot_and_each_drives_only_its_own_cmd_vel(fleet, page):
    server, peer = fleet
    open_live(page, robot_url(server, "boat"))
    assert shown_robot(page) == ("boat", "boat")
    bar = topbar_rows(page)
    assert bar["rows"] == 1

    drive_once(page, peer, "boat")
    assert any(lin > 0 for _, lin, _ in twists(peer, "/boat/cmd_vel"))
    assert all(lin == 0 and ang == 0 for _, lin, ang in twists(peer, "/drone/cmd_vel"))

    # The selector keeps the page: the dashboard, now the drone's.
    with page.expect_navigation():
        page.select_option("#robot-select", label="drone")
    assert page.url == robot_url(server, "drone")
    open_live(page, page.url)  # the same page, waiting for its streams (goto of the current URL)
    assert shown_robot(page) == ("drone", "drone")
    assert topbar_rows(page) == bar

    peer.clear("/boat/cmd_vel")
    peer.clear("/drone/cmd_vel")
    drive_once(page, peer, "drone")
    assert any(lin > 0 for _, lin, _ in twists(peer, "/drone/cmd_vel"))
    assert all(lin == 0 and ang == 0 for _, lin, ang in twists(peer, "/boat/cmd_vel"))
    assert page.watch.offhost == []
    assert page.watch.console_errors == []


def test_selector_keeps_the_page_and_its_query(fleet, page):
    server, _ = fleet
    open_live(page, robot_url(server, "drone", "/topics?topic=%2Fdrone%2Fodom"), drive=False)
    with page.expect_navigation():
        page.select_option("#robot-select", label="boat")
    assert page.url == robot_url(server, "boat", "/topics?topic=%2Fdrone%2Fodom")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert shown_robot(page) == ("boat", "boat")


@pytest.mark.parametrize("width", [1280, 375])  # a desktop's one line; a phone's fixed rows
def test_stop_all_engages_every_robot_and_the_bar_keeps_its_height(fleet, page, width):
    server, _ = fleet
    page.set_viewport_size({"width": width, "height": 800})
    open_live(page, robot_url(server, "drone"))
    before = topbar_rows(page)
    if width > 700:
        assert before["rows"] == 1
    posted = []
    page.on("request", lambda r: r.method == "POST" and posted.append(r.url))
    page.locator("#estop-all-engage").click()
    page.wait_for_selector("#estop-all[data-state='done']", timeout=10000)
    assert page.locator("#estop-all-note").inner_text() == "e-stop engaged: boat and drone"
    assert posted == [server.url + "/api/estop/all"]  # the app's, not under the page's robot
    for name in ("boat", "drone"):
        assert requests.get(robot_url(server, name, "/api/estop"), timeout=5).json()["engaged"] is True
    page.wait_for_selector("#estop[data-engaged='yes']", timeout=5000)  # the page's own robot, over its SSE
    assert page.locator("#estop-release").is_visible()
    assert topbar_rows(page) == before  # the engaged e-stop, Release and the note changed nothing
    assert page.evaluate("document.documentElement.scrollWidth") <= width  # and nothing left the screen
    assert page.watch.console_errors == []


def fix(lng, lat):
    return {"header": {"frame_id": "gps"}, "status": {"status": 0, "service": 1},
            "latitude": lat, "longitude": lng, "altitude": 2.0, "position_covariance_type": 0}


def battery(fraction, volts):
    return {"header": {"frame_id": "battery"}, "percentage": fraction, "voltage": volts,
            "power_supply_status": 2, "present": True}


def publish_until(page, server, peer, topic, msg, seen):
    """Discovery matches the two ends a moment apart: publish until /api/robots shows it."""
    def landed():
        peer.publish(topic, msg)
        robots = requests.get(server.url + "/api/robots", timeout=5).json()["robots"]
        return seen({r["name"]: r for r in robots})
    wait_until(page, landed, what=f"{topic} on /api/robots")


def test_fleet_page_maps_every_robot_and_follows_their_state(fleet, page):
    server, peer = fleet
    published = (("/boat/fix", NAV_SAT_FIX), ("/drone/fix", NAV_SAT_FIX), ("/boat/battery_state", BATTERY_STATE))
    for topic, kind in published:
        peer.advertise(topic, kind)
        peer.wait_match(topic)
    publish_until(page, server, peer, "/boat/fix", fix(*BOAT_AT), lambda r: r["boat"]["position"])
    publish_until(page, server, peer, "/drone/fix", fix(*DRONE_AT), lambda r: r["drone"]["position"])
    publish_until(page, server, peer, "/boat/battery_state", battery(0.87, 24.1), lambda r: r["boat"]["battery"])

    open_live(page, server.url + "/robots", drive=False)
    page.wait_for_selector("#fleet-map[data-ready='yes']", timeout=10000)
    for name, (lng, lat) in (("boat", BOAT_AT), ("drone", DRONE_AT)):
        marker = page.locator(f".fleet-marker[data-robot='{name}']")
        marker.wait_for(timeout=5000)
        assert float(marker.get_attribute("data-lng")) == pytest.approx(lng)
        assert float(marker.get_attribute("data-lat")) == pytest.approx(lat)
        assert marker.inner_text() == name
        assert marker.is_visible()  # framed: both robots in view
    rows = {name: page.locator(f"#fleet-table tr[data-robot='{name}']") for name in ("boat", "drone")}
    assert rows["boat"].locator("[data-field='battery']").inner_text() == "87% · 24.10 V"
    assert rows["drone"].locator("[data-field='battery']").inner_text() == "—"

    # Kept current by polling: one robot's e-stop shows on its row and marker only.
    requests.post(robot_url(server, "boat", "/api/estop"), json={"engaged": True, "by": "curl"}, timeout=5)
    page.wait_for_selector("#fleet-table tr[data-robot='boat'][data-estop='engaged']", timeout=5000)
    page.wait_for_selector(".fleet-marker[data-robot='boat'][data-estop='engaged']", timeout=5000)
    assert rows["drone"].get_attribute("data-estop") == "released"
    assert rows["boat"].locator("[data-field='mode']").inner_text() == "e-stop"

    # A hidden tab asks for nothing until it is shown again.
    page.evaluate("""() => {
        Object.defineProperty(document, 'hidden', {value: true, configurable: true});
        document.dispatchEvent(new Event('visibilitychange'));
    }""")
    asked = []
    page.on("request", lambda r: "/api/robots" in r.url and asked.append(r.url))
    page.wait_for_timeout(2500)
    assert asked == []
    page.evaluate("() => { delete document.hidden; document.dispatchEvent(new Event('visibilitychange')); }")
    wait_until(page, lambda: asked, what="polling again once shown")

    # A robot's marker opens its dashboard.
    with page.expect_navigation():
        page.locator(".fleet-marker[data-robot='drone']").click()
    assert page.url == robot_url(server, "drone")
    assert page.watch.offhost == []
    assert page.watch.console_errors == []


def test_dashboard_robot_card_shows_the_battery_live(fleet, page):
    server, peer = fleet
    peer.advertise("/drone/battery_state", BATTERY_STATE)
    peer.wait_match("/drone/battery_state")
    open_live(page, robot_url(server, "drone"), drive=False)
    assert page.locator("#odom-battery-percent").inner_text() == "—"  # nothing published yet
    assert page.locator("#odom-battery-voltage").inner_text() == "—"

    def shown():
        peer.publish("/drone/battery_state", battery(0.42, 11.7))
        return page.locator("#odom-battery-percent").inner_text() == "42"
    wait_until(page, shown, what="the battery on the Robot card")
    assert page.locator("#odom-battery-voltage").inner_text() == "11.70"
    page.reload()  # rendered with it by the server too
    assert page.locator("#odom-battery-percent").inner_text() == "42"
    open_live(page, robot_url(server, "boat"), drive=False)
    assert page.locator("#odom-battery-percent").inner_text() == "—"  # the boat published none


def test_one_robot_shows_no_selector_and_no_stop_all(live_server, page):
    open_live(page, live_server.url + "/")
    assert page.title() == "Dashboard · rover_web"
    assert page.locator("#robot-select").count() == 0
    assert page.locator("#estop-all").count() == 0
    assert page.locator("#estop-engage").is_visible()
    assert topbar_rows(page)["rows"] == 1


def test_a_viewer_may_stop_all(live_server_factory, page, tmp_path):
    """Engaging is anyone's: a signed-in viewer's Stop all stops every robot."""
    from tests.browser.test_auth import sign_in
    from tests.support.auth import add_users

    db_path = tmp_path / "signed.sqlite3"
    tokens = add_users(db_path)
    server = live_server_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path))
    sign_in(page, server.url, "viewer")
    open_live(page, robot_url(server, "drone"), drive=False)
    assert shown_robot(page) == ("drone", "drone")
    assert page.locator("body").get_attribute("data-can-operate") == "no"
    page.locator("#estop-all-engage").click()
    page.wait_for_selector("#estop-all[data-state='done']", timeout=10000)
    for name in ("boat", "drone"):
        latch = requests.get(robot_url(server, name, "/api/estop"), timeout=5,
                             headers={"Authorization": f"Bearer {tokens['viewer']}"}).json()
        assert latch["engaged"] is True and latch["by"] == "viewer"
    assert page.watch.console_errors == []


def test_fleet_pages_keep_the_content_security_policy(live_server_factory, browser):
    """As tests/browser/test_csp.py, for what several robots add: the selector, Stop all, the fleet map."""
    from tests.conftest import PageWatch

    server = live_server_factory(ROVER_WEB_ROBOTS=ROBOTS)
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # bypass_csp stays off
    try:
        page = context.new_page()
        watch = PageWatch(page)
        page.goto(server.url + "/robots")
        page.wait_for_selector("#fleet-map[data-ready='yes']", timeout=10000)
        with page.expect_navigation():
            page.select_option("#robot-select", label="drone")  # robot_select.js ran under the policy
        assert page.url == robot_url(server, "drone", "/robots")
        page.goto(robot_url(server, "drone"))
        page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
        page.locator("#estop-all-engage").click()
        page.wait_for_selector("#estop-all[data-state='done']", timeout=10000)
        assert watch.console_errors == [], watch.console_errors
        assert watch.offhost == []
    finally:
        context.close()


def test_driving_keys_on_the_selector_never_switch_the_robot(fleet, page):
    """A closed <select> picks by key ("d" jumps to the drone, arrows step): on the selector those
    keys only leave it, and from the next press the keyboard drives the robot shown."""
    server, peer = fleet
    open_live(page, robot_url(server, "boat"))
    page.focus("#robot-select")
    page.keyboard.press("d")
    page.focus("#robot-select")
    page.keyboard.press("ArrowDown")
    page.wait_for_timeout(300)  # a navigation would have begun by now
    assert page.url == robot_url(server, "boat")
    assert shown_robot(page) == ("boat", "boat")
    assert page.evaluate("document.activeElement.id") != "robot-select"
    page.keyboard.down("w")
    peer.wait_for("/boat/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5.0)
    page.keyboard.up("w")
    peer.wait_for("/boat/cmd_vel", is_zero, timeout=2.0)
    assert all(lin == 0 and ang == 0 for _, lin, ang in twists(peer, "/drone/cmd_vel"))
    # Opening the list (Alt+Down) still lets a keyboard choose.
    page.focus("#robot-select")
    page.keyboard.press("Alt+ArrowDown")
    with page.expect_navigation():
        page.keyboard.press("ArrowDown")
        page.keyboard.press("Enter")
    assert page.url == robot_url(server, "drone")
