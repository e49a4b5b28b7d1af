"""The GPS waypoints map in a real Chromium: click, drag, delete, live updates, the robot's fix, and
the offline basemap; nothing ever leaves 127.0.0.1 and the console stays free of errors."""

import io
import subprocess
import sys
import time

import numpy as np
import pytest

from rover_web.config import ROOT
from tests.support.rospeer import subprocess_env
from tests.support.waypoint_helpers import FLOAT64_MULTI_ARRAY, TileServer, stored_rows, warm_up_topic

pytestmark = pytest.mark.browser



def open_map(page, url):
    page.goto(url + "/")
    page.wait_for_selector("#wp-map[data-ready='yes']", timeout=30000)
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    page.locator("#waypoints-card").scroll_into_view_if_needed()  # other panels may come first
    page.wait_for_timeout(200)


def unproject(page, x, y):
    """The map's own idea of the lng/lat under page point (x, y)."""
    return page.evaluate("""([x, y]) => {
        const r = document.getElementById('wp-map').getBoundingClientRect();
        return window.roverWaypointsMap.unproject([x - r.left, y - r.top]).wrap().toArray();
    }""", [x, y])


def wait_until(page, predicate, timeout=10.0, what="condition"):
    """Poll with the page's own timer: Playwright's sync API only serves the page's requests (routed
    through PageWatch) while the test is inside a Playwright call, never during time.sleep."""
    deadline = time.monotonic() + timeout
    while not predicate():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        page.wait_for_timeout(50)


def test_click_adds_drag_moves_delete_removes_and_other_browsers_follow(live_server_factory, ros_peer, page,
                                                                         browser, tmp_path):
    server = live_server_factory(ROVER_WEB_MAP_TILES=str(tmp_path / "no-basemap"),
                                 ROVER_WEB_MAP_GEOJSON_DIR=str(tmp_path / "no-drawn-basemap"))
    db = server.app.config["ROVER_WEB_DB_PATH"]
    peer = ros_peer("waypoint_listener")
    peer.subscribe("/waypoints", FLOAT64_MULTI_ARRAY, qos=1000)
    peer.wait_match("/waypoints")
    warm_up_topic(server.url, peer)
    requests_seen = []
    page.on("request", lambda r: requests_seen.append(r.url))
    open_map(page, server.url)
    other_context = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True)
    try:
        other = other_context.new_page()
        other.watch = type(page.watch)(other)
        open_map(other, server.url)
        assert page.locator("#wp-map-note").is_visible()  # says that no basemap is installed
        assert "Nathan Benderson Park" in page.locator("#wp-place").inner_text()
        assert page.locator("#wp-center").inner_text() == "27.3742443° N, 82.4500873° W"

        # Click: a numbered marker, a list entry, a row in SQLite, a message on /waypoints.
        box = page.locator("#wp-map").bounding_box()
        cx, cy = box["x"] + box["width"] * 0.35, box["y"] + box["height"] * 0.55
        expected = unproject(page, cx, cy)
        page.mouse.click(cx, cy)
        page.wait_for_selector("#wp-list li")
        wait_until(page, lambda: len(stored_rows(db)) == 1, what="the stored waypoint")
        _, lng, lat, _ = stored_rows(db)[0]
        assert lng == pytest.approx(expected[0], abs=1e-4) and lat == pytest.approx(expected[1], abs=1e-4)
        assert peer.wait_for("/waypoints")["msg"]["data"] == [lng, lat]
        assert page.locator(".wp-marker").inner_text() == "1"
        assert page.locator("#wp-list li .wp-num").inner_text() == "1"
        other.wait_for_selector("#wp-list li .wp-coords")  # the other browser follows live
        other.wait_for_selector(".wp-marker")

        # Drag the marker: the waypoint moves, in the list, SQLite and the other browser; no new message.
        marker = page.locator(".wp-marker").bounding_box()
        mx, my = marker["x"] + marker["width"] / 2, marker["y"] + marker["height"] / 2
        target = unproject(page, mx + 120, my - 60)
        page.mouse.move(mx, my)
        page.mouse.down()
        page.mouse.move(mx + 60, my - 30, steps=5)
        page.mouse.move(mx + 120, my - 60, steps=5)
        page.mouse.up()
        wait_until(page, lambda: stored_rows(db)[0][1] != lng, what="the moved waypoint")
        _, lng2, lat2, _ = stored_rows(db)[0]
        assert lng2 == pytest.approx(target[0], abs=2e-4) and lat2 == pytest.approx(target[1], abs=2e-4)
        assert lng2 > lng and lat2 > lat
        text = f"{abs(lat2):.7f}° N, {abs(lng2):.7f}° W"
        page.wait_for_function("t => document.querySelector('#wp-list .wp-coords').textContent === t", arg=text)
        other.wait_for_function("t => document.querySelector('#wp-list .wp-coords').textContent === t", arg=text)
        assert len(stored_rows(db)) == 1
        page.wait_for_timeout(300)
        assert len(peer.received("/waypoints")) == 1

        # A second click makes marker 2; the popup of marker 1 deletes it and 2 becomes 1.
        page.mouse.click(box["x"] + box["width"] * 0.7, box["y"] + box["height"] * 0.3)
        page.wait_for_function("() => document.querySelectorAll('.wp-marker').length === 2")
        page.locator(".wp-marker", has_text="1").click()
        page.locator(".wp-popup button", has_text="Delete").click()
        page.wait_for_function("() => document.querySelectorAll('.wp-marker').length === 1")
        wait_until(page, lambda: len(stored_rows(db)) == 1, what="the deletion")
        assert page.locator(".wp-marker").inner_text() == "1"
        other.wait_for_function("() => document.querySelectorAll('#wp-list li').length === 1")

        for p in (page, other):
            assert p.watch.offhost == []
            assert p.watch.console_errors == []
        assert not [u for u in requests_seen if "/tiles/" in u]  # no basemap: no tile requests at all
    finally:
        other_context.close()


def on_map(page) -> dict:
    """Where the robot's marker is inside the map: a notice shown above the map (a slow link's, on a
    loaded machine) moves the whole map down the page, and must not look like the robot moving."""
    marker = page.locator(".wp-robot").bounding_box()
    box = page.locator("#wp-map").bounding_box()
    # The marker's centre (MapLibre anchors it there): its box's corner moves when it changes size.
    return {"x": marker["x"] + marker["width"] / 2 - box["x"], "y": marker["y"] + marker["height"] / 2 - box["y"]}


def test_the_simulated_robot_moves_on_the_map(live_server, sim_process, ros_peer, page):
    sim_process("--start", "0", "0", "0")  # at the GPS origin (Nathan Benderson Park), facing east
    open_map(page, live_server.url)
    page.wait_for_selector("#wp-fix[data-fix='yes']", timeout=20000)
    page.wait_for_selector(".wp-robot")
    lng0 = float(page.locator("#wp-fix").get_attribute("data-lng"))
    lat0 = float(page.locator("#wp-fix").get_attribute("data-lat"))
    assert lng0 == pytest.approx(-82.4500873, abs=1e-6) and lat0 == pytest.approx(27.3742443, abs=1e-6)
    page.evaluate("([lng, lat]) => window.roverWaypointsMap.jumpTo({center: [lng, lat], zoom: 19})", [lng0, lat0])
    page.wait_for_timeout(300)
    before = on_map(page)

    driver = ros_peer("driver")
    driver.advertise("/cmd_vel", "geometry_msgs/msg/Twist")
    driver.wait_match("/cmd_vel")
    for _ in range(30):  # 3 m/s east for about three seconds (the sim stops 0.5 s after the last one)
        driver.publish("/cmd_vel", {"linear": {"x": 3.0}})
        page.wait_for_timeout(100)
    page.wait_for_function(f"() => Number(document.getElementById('wp-fix').dataset.lng) > {lng0 + 5e-5}",
                           timeout=10000)
    page.wait_for_timeout(500)
    after = on_map(page)
    assert after["x"] - before["x"] > 20, (before, after)  # east is right on the screen
    assert abs(after["y"] - before["y"]) < 10
    fix = live_server.rover.hub.latest("fix")
    assert len(fix["track"]) > 3 and fix["track"][-1][0] > fix["track"][0][0]
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_fetched_tiles_show_on_the_map_with_the_tile_server_stopped(live_server_factory, page, tmp_path):
    from PIL import Image

    tiles = tmp_path / "tiles"
    tile_server = TileServer()
    try:
        run = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "tiles", "fetch",
                              "--bbox", "-82.475,27.358,-82.425,27.391", "--zoom", "13-15",
                              "--url", tile_server.template, "--out", str(tiles)],
                             env=subprocess_env(), cwd=ROOT, capture_output=True, text=True, timeout=120)
        assert run.returncode == 0, run.stdout + run.stderr
    finally:
        tile_server.stop()
    tile_server_url = tile_server.url
    server = live_server_factory(ROVER_WEB_MAP_TILES=str(tiles))
    served = []
    page.on("response", lambda r: "/tiles/" in r.url and served.append((r.url, r.status)))
    requests_seen = []
    page.on("request", lambda r: requests_seen.append(r.url))
    open_map(page, server.url)
    page.wait_for_function("() => window.roverWaypointsMap.areTilesLoaded()", timeout=20000)
    page.wait_for_timeout(500)
    assert page.locator("#wp-map-note").is_hidden()
    assert served and all(status == 200 for _, status in served), served
    assert all(url.startswith(server.url + "/tiles/") for url, _ in served)
    assert not [u for u in requests_seen if u.startswith(tile_server_url)]
    shot = np.asarray(Image.open(io.BytesIO(page.locator("#wp-map").screenshot())).convert("RGB")).astype(int)
    magenta = ((shot[..., 0] > 200) & (shot[..., 2] > 200) & (shot[..., 1] < 90)).mean()
    assert magenta > 0.6, f"only {magenta:.0%} of the map shows the fetched tiles"
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_the_waypoints_table_reads_without_javascript(live_server, browser):
    for lng, lat, label in [(-82.45, 27.37, "start"), (-82.44, 27.38, "finish")]:
        live_server.app.test_client().post("/api/waypoints", json={"lng": lng, "lat": lat, "label": label})
    context = browser.new_context(java_script_enabled=False)
    try:
        page = context.new_page()
        page.goto(live_server.url + "/waypoints")
        rows = page.locator("#waypoints-table tbody tr").all_inner_texts()
        assert [r.split("\t")[:4] for r in rows] == [["1", "start", "27.3700000", "-82.4500000"],
                                                     ["2", "finish", "27.3800000", "-82.4400000"]]
    finally:
        context.close()
