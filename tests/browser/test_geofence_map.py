"""The geofence on the GPS map in a real Chromium: draw a keep-in area and save it, a click outside it
is refused with the server's message, vertices move, areas are deleted, and a file imports. With
sign-in on, an operator sees the editor disabled with the reason; an admin edits and saves, and a
save after the admin's role was lowered shows the server's 403."""

import json

import pytest
import requests

from rover_web.auth import AuthService
from tests.browser.test_auth import sign_in
from tests.browser.test_waypoints_map import open_map, unproject, wait_until
from tests.support.auth import add_users
from tests.support.geofence_helpers import FENCE
from tests.support.waypoint_helpers import stored_rows

pytestmark = pytest.mark.browser


def fence(url, token=None):
    headers = {"Authorization": f"Bearer {token}"} if token else {}
    return requests.get(url + "/api/geofence", headers=headers, timeout=5).json()


def test_draw_a_fence_then_a_click_outside_it_is_refused_visibly(live_server_factory, page, tmp_path):
    server = live_server_factory(ROVER_WEB_MAP_TILES=str(tmp_path / "no-basemap"))
    db = server.app.config["ROVER_WEB_DB_PATH"]
    open_map(page, server.url)
    page.wait_for_selector("#gf-editor[data-ready='yes']")
    box = page.locator("#wp-map").bounding_box()

    def at(fx, fy):
        return box["x"] + box["width"] * fx, box["y"] + box["height"] * fy

    # Draw a keep-in square over the middle of the map and save it.
    page.locator("#gf-edit").check()
    page.locator("#gf-draw-in").click()
    corners = [at(0.3, 0.3), at(0.6, 0.3), at(0.6, 0.7), at(0.3, 0.7)]
    expected = [unproject(page, *c) for c in corners]
    for c in corners:
        page.mouse.click(*c)
    page.locator("#gf-finish").click()
    assert stored_rows(db) == []  # clicks while drawing add no waypoint
    page.locator("#gf-save").click()
    page.wait_for_selector("#gf-editor[data-revision='1']")
    saved = fence(server.url)
    ring = saved["features"][0]["geometry"]["coordinates"][0]
    assert saved["features"][0]["properties"] == {"kind": "keep_in"} and len(ring) == 5
    for got, want in zip(ring, expected, strict=False):
        assert got == pytest.approx(want, abs=1e-4)  # a pixel or so
    drawn = page.evaluate("() => window.roverWaypointsMap.querySourceFeatures('fence').length")
    assert drawn >= 1

    # Back to waypoints: a click outside is refused with the server's words, nothing stored.
    page.locator("#gf-edit").uncheck()
    page.mouse.click(*at(0.85, 0.5))
    page.wait_for_selector("#wp-message[data-kind='error']")
    shown = page.locator("#wp-message").inner_text()
    assert "outside every keep-in area of the geofence" in shown
    assert page.locator("#wp-message").is_visible()
    page.wait_for_timeout(200)
    assert stored_rows(db) == [] and page.locator(".wp-marker").count() == 0
    page.mouse.click(*at(0.45, 0.5))  # inside: added
    page.wait_for_selector(".wp-marker")
    wait_until(page, lambda: len(stored_rows(db)) == 1, what="the allowed waypoint")

    # Select the area and drag a vertex outwards: saved, the fence grows.
    page.locator("#gf-edit").check()
    page.mouse.click(*at(0.35, 0.35))
    page.wait_for_function("() => document.querySelectorAll('.gf-vertex').length === 4")
    vertex = page.locator(".gf-vertex").nth(1).bounding_box()  # the north-east corner
    vx, vy = vertex["x"] + vertex["width"] / 2, vertex["y"] + vertex["height"] / 2
    page.mouse.move(vx, vy)
    page.mouse.down()
    page.mouse.move(vx + 50, vy - 20, steps=5)
    page.mouse.move(vx + 100, vy - 40, steps=5)
    page.mouse.up()
    page.wait_for_selector("#gf-editor[data-dirty='yes']")
    page.locator("#gf-save").click()
    page.wait_for_selector("#gf-editor[data-revision='2']")
    moved = fence(server.url)["features"][0]["geometry"]["coordinates"][0]
    assert moved[1][0] > ring[1][0] and moved[1][1] > ring[1][1] and moved[0] == moved[-1]

    # Delete it: with no fence, the same outside click is allowed.
    page.mouse.click(*at(0.35, 0.35))
    page.locator("#gf-delete").click()
    page.locator("#gf-save").click()
    page.wait_for_selector("#gf-editor[data-revision='3']")
    assert fence(server.url)["features"] == []
    page.locator("#gf-edit").uncheck()
    page.mouse.click(*at(0.85, 0.5))
    wait_until(page, lambda: len(stored_rows(db)) == 2, what="the waypoint outside the former fence")

    # Import a fence file: shown; a bad file's refusal is shown and changes nothing.
    good, bad = tmp_path / "fence.geojson", tmp_path / "bowtie.geojson"
    good.write_text(json.dumps(FENCE))
    bad.write_text(json.dumps({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {
        "kind": "keep_out", "name": "bowtie"}, "geometry": {"type": "Polygon", "coordinates": [
            [[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]]]}}]}))
    page.locator("#gf-import").set_input_files(str(good))
    page.wait_for_selector("#gf-editor[data-revision='4'][data-areas='2']")
    page.locator("#gf-import").set_input_files(str(bad))
    page.wait_for_selector("#gf-message[data-kind='error']")
    assert "bowtie" in page.locator("#gf-message").inner_text()
    assert fence(server.url)["revision"] == 4
    assert page.watch.offhost == []


def signed_map_server(live_server_factory, tmp_path):
    db_path = tmp_path / "signed.sqlite3"
    tokens = add_users(db_path)
    server = live_server_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path),
                                 ROVER_WEB_MAP_TILES=str(tmp_path / "no-basemap"))
    server.tokens = tokens
    return server


EDIT_CONTROLS = ["#gf-edit", "#gf-draw-in", "#gf-draw-out", "#gf-finish", "#gf-delete", "#gf-save", "#gf-revert",
                 "#gf-import"]


def test_an_operator_sees_the_fence_editor_disabled_with_the_reason(live_server_factory, page, tmp_path):
    server = signed_map_server(live_server_factory, tmp_path)
    sign_in(page, server.url, "operator")
    open_map(page, server.url)
    page.wait_for_selector("#gf-editor[data-ready='yes']")
    assert page.locator("#gf-editor").get_attribute("data-may-edit") == "no"
    assert page.locator("#gf-admin-only").is_visible()
    assert page.locator("#gf-admin-only").inner_text() == "Only an admin may change the geofence."
    for control in EDIT_CONTROLS:
        assert page.locator(control).is_disabled(), control
    # The operator's other work is untouched: a map click still adds a waypoint.
    box = page.locator("#wp-map").bounding_box()
    page.mouse.click(box["x"] + box["width"] * 0.5, box["y"] + box["height"] * 0.5)
    page.wait_for_selector(".wp-marker")
    assert fence(server.url, server.tokens["operator"])["revision"] == 0
    assert page.watch.offhost == []


def test_an_admin_edits_and_saves_and_a_lowered_role_meets_the_servers_refusal(live_server_factory, page, tmp_path):
    server = signed_map_server(live_server_factory, tmp_path)
    sign_in(page, server.url, "admin")
    open_map(page, server.url)
    page.wait_for_selector("#gf-editor[data-ready='yes']")
    assert page.locator("#gf-editor").get_attribute("data-may-edit") == "yes"
    assert page.locator("#gf-admin-only").count() == 0
    assert page.locator("#gf-edit").is_enabled() and page.locator("#gf-import").is_enabled()
    box = page.locator("#wp-map").bounding_box()

    def at(fx, fy):
        return box["x"] + box["width"] * fx, box["y"] + box["height"] * fy

    page.locator("#gf-edit").check()
    page.locator("#gf-draw-out").click()
    for c in [at(0.3, 0.3), at(0.6, 0.3), at(0.6, 0.7), at(0.3, 0.7)]:
        page.mouse.click(*c)
    page.locator("#gf-finish").click()
    page.locator("#gf-save").click()
    page.wait_for_selector("#gf-editor[data-revision='1']")
    assert fence(server.url, server.tokens["viewer"])["features"][0]["properties"] == {"kind": "keep_out"}

    # The admin becomes an operator while the page is open: the page still offers the editor, and
    # the server's refusal is what the operator reads. Nothing changes.
    server.rover.feature(AuthService).accounts.set_role("admin", "operator")
    page.mouse.click(*at(0.45, 0.5))  # select the area
    page.locator("#gf-delete").click()
    page.locator("#gf-save").click()
    page.wait_for_selector("#gf-message[data-kind='error']")
    shown = page.locator("#gf-message").inner_text()
    # A role change ends the user's sessions (docs/security.md): the server's refusal is a 401
    # asking to sign in again, shown in its own words.
    assert shown.startswith("Fence not saved: ") and "sign in" in shown
    assert fence(server.url, server.tokens["viewer"])["revision"] == 1
    assert page.watch.offhost == []


def test_livemap_draws_keep_out_areas_and_a_goal_inside_one_is_refused(live_server, page):
    from tests.browser.test_livemap import canvas_origin, canvas_rgb, expected_screen
    from tests.browser.test_livemap import open_map as open_livemap

    s = open_livemap(page, live_server.url)
    assert s["keep_out"] == 1
    x, y = expected_screen(s, 35.75, 2.0)  # the middle of the electrical room
    r, g, b = canvas_rgb(page, x, y)
    assert r > g + 40 and r > b + 40  # tinted red
    left, top = canvas_origin(page)
    page.click("#livemap-goal-mode")
    page.mouse.click(left + x, top + y)
    page.wait_for_function("() => /Goal refused: .*electrical room/.test(document.body.innerText)")
    assert page.evaluate("window.liveMapState.goal") is None


def test_every_page_shows_the_breach_banner_live(live_server, page):
    from rover_web.geofence import GeofenceService
    from tests.support.geofence_helpers import INSIDE, OUTSIDE

    requests.put(live_server.url + "/api/geofence", json=FENCE, timeout=5).raise_for_status()
    watch = live_server.rover.feature(GeofenceService)
    page.goto(live_server.url + "/topics")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert page.locator("#geofence-banner").is_hidden()
    # What the /fix callback does with a position (tests/integration/geofence/test_ros.py sends
    # real NavSatFix messages from another process).
    watch.note_position(*OUTSIDE)
    page.wait_for_selector("#geofence-banner", state="visible")
    assert "outside every keep-in area" in page.locator("#geofence-banner").inner_text()
    watch.note_position(*INSIDE)
    page.wait_for_selector("#geofence-banner", state="hidden")
