"""The LiveMap HTTP API: map list, map_state, images, goals, and every kind of bad input."""

import io
import math
import re
import time
from urllib.parse import quote

import pytest
from PIL import Image

from rover_web.core.state import EXTENSION
from rover_web.livemap.service import LiveMapService

BASEMENT = "Science Hall Basement"
LAB = "Robotics Lab"
B = quote(BASEMENT)


def test_map_list_names_sizes_and_links(client):
    body = client.get("/api/maps").json
    assert body["default"] == BASEMENT
    maps = {m["name"]: m for m in body["maps"]}
    assert list(maps) == [BASEMENT, LAB]
    basement = maps[BASEMENT]
    assert (basement["width_px"], basement["height_px"], basement["resolution_m"]) == (800, 480, 0.05)
    assert (basement["width_m"], basement["height_m"], basement["origin"]) == (40.0, 24.0, [-2.0, -1.5, 0.0])
    assert basement["urls"] == {"state": f"/api/maps/{B}", "image": f"/api/maps/{B}/image",
                                "thumbnail": f"/api/maps/{B}/thumbnail", "page": f"/livemap/{B}",
                                "goal": f"/api/maps/{B}/goal", "initial_pose": f"/api/maps/{B}/initial_pose"}
    for m in maps.values():
        thumb = client.get(m["urls"]["thumbnail"])
        assert thumb.status_code == 200 and thumb.mimetype == "image/png"
        with Image.open(io.BytesIO(thumb.data)) as image:
            assert max(image.size) == 320
            assert image.size[0] / image.size[1] == pytest.approx(m["width_px"] / m["height_px"], rel=0.02)


def test_map_state_at_a_requested_scale(client):
    state = client.get(f"/api/maps/{B}?cm_per_pixel=2").json
    params, scaled = state["map_parameters"], state["scaled_pixel_values"]
    assert params["map_name"] == BASEMENT and params["cm_per_pixel"] == 2.0
    assert params["files"]["png"]["pixel_width"] == 800 and params["files"]["png"]["pixel_height"] == 480
    assert params["files"]["yaml"]["resolution"] == 0.05
    assert scaled["png_pixel_width"] == 2000.0 and scaled["png_pixel_height"] == 1200.0
    assert scaled["bot_radius"] == pytest.approx(8.85)
    dock = next(w for w in scaled["waypoints"] if w["name"] == "Dock")
    assert (dock["x"], dock["y"]) == pytest.approx((200.0, 600.0))   # (2, 10.5) m: pixel (80, 240), x2.5
    native = client.get(f"/api/maps/{B}").json["scaled_pixel_values"]
    assert native["cm_per_pixel"] == 5.0 and native["png_pixel_width"] == 800


def test_images_are_png_of_the_map_size_with_revalidation(client):
    for name, size in ((BASEMENT, (800, 480)), (LAB, (480, 360))):  # the lab is a PGM on disk
        response = client.get(f"/api/maps/{quote(name)}/image")
        assert response.status_code == 200 and response.mimetype == "image/png"
        with Image.open(io.BytesIO(response.data)) as image:
            assert image.format == "PNG" and image.size == size
        again = client.get(f"/api/maps/{quote(name)}/image", headers={"If-None-Match": response.headers["ETag"]})
        assert again.status_code == 304


@pytest.mark.parametrize("query", ["cm_per_pixel=0", "cm_per_pixel=-2", "cm_per_pixel=nan", "cm_per_pixel=inf",
                                   "cm_per_pixel=two", "cm_per_pixel=1e999"])
def test_bad_scales_are_400(client, query):
    response = client.get(f"/api/maps/{B}?{query}")
    assert response.status_code == 400 and response.json["error"] in ("out_of_range", "bad_type")


@pytest.mark.parametrize("path", [
    "/api/maps/Attic", "/api/maps/Attic/image", "/api/maps/Attic/thumbnail",
    "/api/maps/..%2F..%2Fetc%2Fpasswd", "/api/maps/..%2Fall_maps.json/image", "/api/maps/%2E%2E/image",
    "/api/maps/basement%2Fbasement.png/image", "/api/maps/..%5C..%5Cwin.ini/image",
    "/api/maps/..", "/api/maps/../../etc/passwd", f"/api/maps/{B}/..%2F..%2Fall_maps.json",
])
def test_unknown_maps_and_traversal_attempts_are_json_404(client, path):
    response = client.get(path)
    assert response.status_code == 404
    assert response.is_json and response.json["error"] in ("unknown_map", "not_found")
    assert b"root:" not in response.data and b"Gerstenzang" not in response.data


def test_unknown_map_page_is_404_and_livemap_redirects_to_the_default(client):
    assert client.get("/livemap/Attic").status_code == 404
    response = client.get("/livemap")
    assert response.status_code == 302 and response.location.endswith(f"/livemap/{B}")
    page = client.get(f"/livemap/{B}")
    assert page.status_code == 200 and b'id="livemap-canvas"' in page.data
    assert b'id="livemap-data"' in page.data and BASEMENT.encode() in page.data


def test_dashboard_has_a_thumbnail_linking_to_the_map_and_a_nav_link(client):
    html = client.get("/").data.decode()
    assert f'href="/livemap/{B}"' in html and f'src="/api/maps/{B}/thumbnail"' in html
    assert 'href="/livemap"' in html


GOAL = "geometry_msgs/msg/PoseStamped"


def warm_up_goal(client, peer, name=BASEMENT, timeout=10.0):
    """Post goals until the peer hears one (the app's publisher matches a moment after the peer)."""
    deadline = time.monotonic() + timeout
    while not peer.received("/goal_pose"):
        assert time.monotonic() < deadline, "the peer never heard a goal"
        assert client.post(f"/api/maps/{quote(name)}/goal", json={"x": 0.0, "y": 0.0}).status_code == 200
        time.sleep(0.1)
    time.sleep(0.2)
    peer.clear("/goal_pose")


@pytest.mark.ros
def test_a_goal_from_the_api_reaches_a_subscriber_in_frame_map(client, ros_peer):
    peer = ros_peer()
    peer.subscribe("/goal_pose", GOAL)
    peer.wait_match("/goal_pose")
    warm_up_goal(client, peer)
    response = client.post(f"/api/maps/{B}/goal", json={"x": 23.0, "y": 4.0, "yaw": math.pi / 2})
    assert response.status_code == 200
    body = response.json
    assert body["status"] == "sent" and body["topic"] == "/goal_pose"
    assert body["goal"]["pixels"][BASEMENT] == {"x": 500.0, "y": 370.0, "yaw": pytest.approx(math.pi / 2, abs=1e-4),
                                                "inside": True}
    msg = peer.wait_for("/goal_pose", lambda m: m["pose"]["position"]["x"] == 23.0)["msg"]
    assert msg["header"]["frame_id"] == "map"
    assert msg["pose"]["position"]["y"] == 4.0
    q = msg["pose"]["orientation"]
    assert (q["z"], q["w"]) == pytest.approx((math.sin(math.pi / 4), math.cos(math.pi / 4)))
    assert msg["header"]["stamp"]["sec"] > 0
    # The map state shows the goal that was sent.
    goal = client.get(f"/api/maps/{B}").json["map_parameters"]["goal_pose"]
    assert (goal["x"], goal["y"], goal["frame_id"]) == (23.0, 4.0, "map")


@pytest.mark.ros
def test_bad_goals_are_400_and_publish_nothing(client, ros_peer):
    peer = ros_peer()
    peer.subscribe("/goal_pose", GOAL)
    peer.wait_match("/goal_pose")
    warm_up_goal(client, peer)
    before = client.get(f"/api/maps/{B}").json["map_parameters"]["goal_pose"]
    bad_bodies = [
        {"x": 100.0, "y": 4.0},                # east of the basement
        {"x": 23.0, "y": -1.6},                # just south of it
        {"x": 23.0},                           # no y
        {"y": 4.0, "yaw": 0.0},                # no x
        {"x": "23", "y": 4.0},                 # a string
        {"x": True, "y": 4.0},
        {"x": None, "y": 4.0},
        {"x": 23.0, "y": 4.0, "yaw": "north"},
        {"x": 23.0, "y": 4.0, "z": 1.0},       # unknown field
    ]
    for body in bad_bodies:
        response = client.post(f"/api/maps/{B}/goal", json=body)
        assert response.status_code == 400, body
        assert set(response.json) == {"error", "message"}
    for raw in (b'{"x": NaN, "y": 1}', b'{"x": Infinity, "y": 1}', b'{"x": 1e400, "y": 1}', b"[1, 2]", b"{",
                b""):
        response = client.post(f"/api/maps/{B}/goal", data=raw, content_type="application/json")
        assert response.status_code == 400, raw
    outside = client.post(f"/api/maps/{B}/goal", json={"x": 100.0, "y": 4.0}).json
    assert outside["error"] == "outside_map" and "-2..38" in outside["message"]
    assert client.post("/api/maps/Attic/goal", json={"x": 1.0, "y": 1.0}).status_code == 404
    assert client.post(f"/api/maps/{B}/goal", data="x=1", content_type="text/plain").status_code == 415
    assert client.post(f"/api/maps/{B}/goal", json={"x": 1.0, "y": 1.0},
                       headers={"Origin": "http://evil.example"}).status_code == 403
    # A good goal afterwards is the only message the subscriber gets.
    assert client.post(f"/api/maps/{B}/goal", json={"x": 5.0, "y": 5.0, "yaw": 0.0}).status_code == 200
    peer.wait_for("/goal_pose", lambda m: m["pose"]["position"]["x"] == 5.0)
    time.sleep(0.3)
    assert [m["msg"]["pose"]["position"]["x"] for m in peer.received("/goal_pose")] == [5.0]
    assert before["x"] == 0.0  # the warm-up goal stood until the good one replaced it


def test_maps_settings_default_map_single_yaml_and_none(app_factory):
    from rover_web.config import ROOT, ConfigError

    with pytest.raises(ConfigError, match="ROVER_WEB_LIVEMAP_DEFAULT_MAP: no map named 'Attic'"):
        app_factory(ROVER_WEB_LIVEMAP_DEFAULT_MAP="Attic")
    lab_first = app_factory(ROVER_WEB_LIVEMAP_DEFAULT_MAP=LAB).test_client()
    assert lab_first.get("/api/maps").json["default"] == LAB
    assert lab_first.get("/livemap").location.endswith(f"/livemap/{quote(LAB)}")
    one = app_factory(ROVER_WEB_MAPS_FILE=str(ROOT / "map_files" / "lab" / "lab.yaml")).test_client()
    assert [m["name"] for m in one.get("/api/maps").json["maps"]] == ["lab"]
    assert one.get("/api/maps/lab").json["map_parameters"]["files"]["yaml_file"] == "lab.yaml"
    none = app_factory(ROVER_WEB_MAPS_FILE=None).test_client()   # ROVER_WEB_MAPS_FILE= in the environment
    assert none.get("/api/maps").json == {"maps": [], "default": None}
    page = none.get("/livemap")
    assert page.status_code == 200 and b"No map to show yet" in page.data
    assert none.get("/").status_code == 200


def test_the_dashboard_renders_the_robot_dot_with_the_page(app):
    service = app.extensions[EXTENSION].feature(LiveMapService)
    service.on_pose((18.0, 10.5, 0.0, "map", 1.0))   # as the /amcl_pose callback would
    html = app.test_client().get("/").data.decode()
    # The dot's place is data the page's script turns into a position (no inline style: the CSP).
    width = float(re.search(r'id="livemap-thumb"[^>]*data-width="([\d.]+)"', html).group(1))
    height = float(re.search(r'id="livemap-thumb"[^>]*data-height="([\d.]+)"', html).group(1))
    x = float(re.search(r'id="livemap-thumb-robot"[^>]*data-x="([-\d.]+)"', html).group(1))
    y = float(re.search(r'id="livemap-thumb-robot"[^>]*data-y="([-\d.]+)"', html).group(1))
    assert (x / width, y / height) == (0.5, 0.5) and "18.0, 10.5 m" in html
