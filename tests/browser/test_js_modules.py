"""The pages' shared and pure ES modules, imported on their own in Chromium: api.js against real and
fake answers, and the LiveMap's geometry and view maths against rover_web/livemap/geometry.py."""

import math
from urllib.parse import quote

import pytest
import requests

from rover_web.livemap.geometry import MapGeometry

pytestmark = pytest.mark.browser

GOAL_URL = f"/api/maps/{quote('Science Hall Basement')}/goal"

CALL = """async ([method, url, body]) => {
    const { api, ApiError } = await import('/static/js/core/api.js');
    try {
        return { ok: true, reply: await api(method, url, body) };
    } catch (err) {
        return { ok: false, apiError: err instanceof ApiError, name: err.name, message: err.message,
                 status: err.status ?? null, code: err.code ?? null, reply: err.reply ?? null };
    }
}"""


@pytest.fixture
def blank(live_server, page):
    page.goto(live_server.url + "/static/js/core/api.js")  # same origin, and no page script of its own
    return page


def test_api_resolves_to_the_json_reply(live_server, blank):
    got = blank.evaluate(CALL, ["GET", "/api/status", None])
    assert got["ok"] and got["reply"]["node"] == requests.get(live_server.url + "/api/status", timeout=5).json()["node"]


def test_api_error_carries_the_servers_status_code_and_message(live_server, blank):
    server = requests.post(live_server.url + GOAL_URL, json={"x": "east", "y": 0}, timeout=5)
    assert server.status_code == 400
    got = blank.evaluate(CALL, ["POST", GOAL_URL, {"x": "east", "y": 0}])
    assert got == {"ok": False, "apiError": True, "name": "ApiError", "message": server.json()["message"],
                   "status": 400, "code": server.json()["error"], "reply": server.json()}


def test_api_error_from_a_page_that_is_not_json_names_the_status(blank):
    blank.route("**/api/proxied", lambda route: route.fulfill(
        status=502, content_type="text/html", body="<html><body>Bad Gateway</body></html>"))
    got = blank.evaluate(CALL, ["POST", "/api/proxied", {"a": 1}])
    assert got["apiError"] and got["status"] == 502 and got["code"] is None and got["reply"] is None
    assert got["message"].startswith("HTTP 502")


def test_no_answer_is_not_an_api_error(blank):
    blank.route("**/api/away", lambda route: route.abort("connectionrefused"))
    got = blank.evaluate(CALL, ["GET", "/api/away", None])
    assert got["ok"] is False and got["apiError"] is False and got["name"] == "TypeError"


def test_livemap_geometry_matches_the_server_with_a_turned_origin(blank):
    geo = MapGeometry(width_px=800, height_px=480, resolution_m=0.05, origin_x=-3.0, origin_y=2.5, origin_yaw=0.4)
    g = {"w": 800, "h": 480, "res": 0.05, "ox": -3.0, "oy": 2.5, "oyaw": 0.4}
    points = [(0.0, 0.0), (23.0, 4.0), (-7.5, 18.25), (40.0, -2.0)]
    got = blank.evaluate("""async ([g, points]) => {
        const m = await import('/static/js/livemap/geometry.js');
        return points.map(([x, y]) => {
            const [px, py] = m.worldToPixel(g, x, y);
            return { pixel: [px, py], back: m.pixelToWorld(g, px, py), inside: m.insideMap(g, x, y) };
        });
    }""", [g, points])
    for (x, y), js in zip(points, got, strict=True):
        assert js["pixel"] == pytest.approx(geo.world_to_pixel(x, y), abs=1e-9)
        assert js["back"] == pytest.approx((x, y), abs=1e-9)
        assert js["inside"] == geo.contains(x, y)


def test_goal_heading_from_a_drag_and_from_a_click(blank):
    got = blank.evaluate("""async () => {
        const m = await import('/static/js/livemap/geometry.js');
        const g = { w: 10, h: 10, res: 1, ox: 0, oy: 0, oyaw: 0.5 };
        return [m.gestureYaw(g, 100, 100, 130, 70, 0, 0, null),      // dragged up and right
                m.gestureYaw(g, 100, 100, 102, 101, 3, 3, { x: 2, y: 2 }),  // a click, facing away from the robot
                m.gestureYaw(g, 100, 100, 100, 100, 3, 3, null)];     // a click without a live pose
    }""")
    assert got == pytest.approx([math.pi / 4 + 0.5, math.pi / 4, 0.0])


def test_view_zoom_keeps_the_floor_under_the_cursor_and_resize_keeps_the_middle(blank):
    got = blank.evaluate("""async () => {
        const v = await import('/static/js/livemap/view.js');
        const g = await import('/static/js/livemap/geometry.js');
        const geo = { w: 800, h: 480, res: 0.05, ox: 0, oy: 0, oyaw: 0 };
        const size = { width: 1000, height: 600 };
        const fit = v.fitView(geo, size);
        const zoomed = v.zoomView(geo, size, fit, 1.25, 300, 200);
        const resized = v.resizeView(fit, size, { width: 1200, height: 500 });
        return { fit, zoomed, before: g.screenToPixel(fit, 300, 200), after: g.screenToPixel(zoomed, 300, 200),
                 middleBefore: g.screenToPixel(fit, 500, 300), middleAfter: g.screenToPixel(resized, 600, 250),
                 tooFar: v.zoomView(geo, size, fit, 1e-6, 0, 0).scale,
                 tooClose: v.zoomView(geo, size, fit, 1e6, 0, 0).scale };
    }""")
    assert got["fit"]["scale"] == pytest.approx(0.96 * min(1000 / 800, 600 / 480))
    assert got["zoomed"]["scale"] == pytest.approx(got["fit"]["scale"] * 1.25)
    assert got["after"] == pytest.approx(got["before"])
    assert got["middleAfter"] == pytest.approx(got["middleBefore"])
    assert got["tooFar"] == pytest.approx(got["fit"]["scale"] / 8)
    assert got["tooClose"] == pytest.approx(max(got["fit"]["scale"] * 64, 40))
