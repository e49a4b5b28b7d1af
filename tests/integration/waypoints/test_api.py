"""The waypoints HTTP API on a real app (its own ROS node, real SQLite): editor, GeoJSON, refusals."""

import json
import re
import sqlite3

import pytest

from rover_web.waypoints.service import WaypointsService
from tests.support.waypoint_helpers import stored_rows


@pytest.fixture
def wp_app(app_factory, tmp_path):
    return app_factory(ROVER_WEB_MAX_WAYPOINTS=4, ROVER_WEB_MAP_TILES=str(tmp_path / "no-tiles"))


@pytest.fixture
def api(wp_app):
    return wp_app.test_client()


def db_path(app):
    return app.config["ROVER_WEB_DB_PATH"]


def mission(api):
    return api.get("/api/waypoints").get_json()


def add(api, lng, lat, label=None):
    body = {"lng": lng, "lat": lat} | ({"label": label} if label is not None else {})
    r = api.post("/api/waypoints", json=body)
    assert r.status_code == 201, r.get_json()
    return r.get_json()["waypoint"]


def test_seed_call_shape_and_it_joins_the_mission(api, wp_app):
    r = api.post("/waypoints", json={"lng": 1.0, "lat": 2.0})
    assert r.status_code == 200
    body = r.get_json()
    assert list(body) == ["status", "message", "waypoint"]
    assert body["status"] == "success" and body["message"] == "Waypoint received"
    assert body["waypoint"] == {"id": body["waypoint"]["id"], "index": 0, "lng": 1.0, "lat": 2.0, "label": ""}
    assert stored_rows(db_path(wp_app)) == [(0, 1.0, 2.0, "")]


def test_editor_list_add_move_reorder_delete_clear(api, wp_app):
    a = add(api, -82.45, 27.37, "start")
    b = add(api, -82.44, 27.38)
    c = add(api, -82.43, 27.39, "end")
    listed = mission(api)
    assert [w["id"] for w in listed["waypoints"]] == [a["id"], b["id"], c["id"]]
    assert listed["count"] == 3 and listed["max"] == 4
    revision = listed["revision"]

    moved = api.patch(f"/api/waypoints/{b['id']}", json={"lng": -82.441, "lat": 27.381})
    assert moved.status_code == 200 and moved.get_json()["revision"] == revision + 1
    assert (moved.get_json()["waypoint"]["lng"], moved.get_json()["waypoint"]["lat"]) == (-82.441, 27.381)
    assert api.patch(f"/api/waypoints/{c['id']}", json={"index": 0, "label": "now first"}).status_code == 200
    assert [(w["id"], w["index"]) for w in mission(api)["waypoints"]] == [(c["id"], 0), (a["id"], 1), (b["id"], 2)]
    assert mission(api)["waypoints"][0]["label"] == "now first"

    assert api.delete(f"/api/waypoints/{a['id']}").status_code == 200
    assert [w["id"] for w in mission(api)["waypoints"]] == [c["id"], b["id"]]
    assert api.delete(f"/api/waypoints/{a['id']}").status_code == 404
    assert api.patch(f"/api/waypoints/{a['id']}", json={"lng": 1}).status_code == 404
    assert stored_rows(db_path(wp_app)) == [(0, -82.43, 27.39, "now first"), (1, -82.441, 27.381, "")]

    cleared = api.delete("/api/waypoints")
    assert cleared.status_code == 200 and cleared.get_json()["deleted"] == 2
    assert mission(api)["waypoints"] == [] and stored_rows(db_path(wp_app)) == []


def test_geojson_round_trip_over_http(api, wp_app):
    add(api, -82.4500873, 27.3742443, "start")
    add(api, -82.4481, 27.3769, "gate ⛵")
    add(api, -82.4462, 27.3751)
    exported = api.get("/api/waypoints/geojson")
    assert exported.status_code == 200 and exported.mimetype == "application/geo+json"
    doc = exported.get_json()
    assert doc["type"] == "FeatureCollection" and len(doc["features"]) == 3
    download = api.get("/api/waypoints/geojson?download=1")
    assert "attachment" in download.headers["Content-Disposition"]

    assert api.delete("/api/waypoints").status_code == 200
    imported = api.post("/api/waypoints/geojson", data=json.dumps(doc), content_type="application/json")
    assert imported.status_code == 200 and imported.get_json()["count"] == 3
    assert api.get("/api/waypoints/geojson").get_json() == doc
    assert [r[1:] for r in stored_rows(db_path(wp_app))] == [
        (-82.4500873, 27.3742443, "start"), (-82.4481, 27.3769, "gate ⛵"), (-82.4462, 27.3751, "")]


def test_get_waypoints_is_a_server_rendered_table(api):
    empty = api.get("/waypoints")
    assert empty.status_code == 200 and b"No waypoints yet" in empty.data
    add(api, -82.4500873, 27.3742443, "<script>alert(1)</script>")
    add(api, -82.44, 27.38, "buoy")
    html = api.get("/waypoints").get_data(as_text=True)
    rows = re.findall(r"<tr data-id=\"\d+\"><td>(\d+)</td><td>(.*?)</td>\s*<td>(.*?)</td><td>(.*?)</td>", html)
    assert rows == [("1", "&lt;script&gt;alert(1)&lt;/script&gt;", "27.3742443", "-82.4500873"),
                    ("2", "buoy", "27.3800000", "-82.4400000")]
    assert "<script>alert" not in html
    assert 'href="/waypoints"' in api.get("/").get_data(as_text=True)  # the nav link


BAD_BODIES = [
    ({}, 400, "missing_field"),
    ({"lat": 2.0}, 400, "missing_field"),
    ({"lng": "1.0", "lat": 2.0}, 400, "bad_type"),
    ({"lng": None, "lat": 2.0}, 400, "bad_type"),
    ({"lng": True, "lat": 2.0}, 400, "bad_type"),
    ({"lng": 1.0, "lat": 90.5}, 400, "out_of_range"),
    ({"lng": -180.01, "lat": 0}, 400, "out_of_range"),
    ({"lng": 1.0, "lat": 2.0, "alt": 3}, 400, "unknown_field"),
    ({"lng": 1.0, "lat": 2.0, "label": "x" * 81}, 400, "too_long"),
    ([1.0, 2.0], 400, "bad_json"),
]


@pytest.mark.parametrize("route", ["/waypoints", "/api/waypoints"])
@pytest.mark.parametrize("body, status, code", BAD_BODIES)
def test_bad_bodies_are_refused_by_name_and_store_nothing(api, wp_app, route, body, status, code):
    r = api.post(route, data=json.dumps(body), content_type="application/json")
    assert (r.status_code, r.get_json()["error"]) == (status, code), r.get_json()
    assert r.get_json()["message"]
    assert mission(api)["revision"] == 0 and stored_rows(db_path(wp_app)) == []


@pytest.mark.parametrize("raw", ['{"lng": NaN, "lat": 1}', '{"lng": 1, "lat": Infinity}', '{"lng": 1e400, "lat": 1}',
                                 '{"lng": 1, "lat": -Infinity}', '{"lng": 1, "lat"', ""])
def test_non_finite_and_malformed_json_are_400(api, wp_app, raw):
    for route in ("/waypoints", "/api/waypoints"):
        r = api.post(route, data=raw, content_type="application/json")
        assert r.status_code == 400 and r.get_json()["error"] in ("non_finite", "bad_json", "missing_body")
    assert stored_rows(db_path(wp_app)) == []


def test_wrong_content_type_is_415_and_a_huge_body_is_413(api, wp_app):
    for route in ("/waypoints", "/api/waypoints", "/api/waypoints/geojson", "/api/waypoints/send"):
        r = api.post(route, data='{"lng": 1, "lat": 2}', content_type="text/plain")
        assert r.status_code == 415 and r.get_json()["error"] == "unsupported_media_type"
        r = api.post(route, data=b'{"lng": 1, "lat": 2, "label": "' + b"x" * 300_000 + b'"}',
                     content_type="application/json")
        assert r.status_code == 413
    assert api.patch("/api/waypoints/1", data="{}", content_type="application/x-www-form-urlencoded").status_code == 415
    assert stored_rows(db_path(wp_app)) == []


def test_the_configured_maximum_is_409_and_stores_nothing_more(api, wp_app):
    for i in range(4):
        add(api, float(i), 0.0)
    for route in ("/waypoints", "/api/waypoints"):
        r = api.post(route, json={"lng": 9.0, "lat": 9.0})
        assert r.status_code == 409 and r.get_json()["error"] == "too_many_waypoints"
        assert "ROVER_WEB_MAX_WAYPOINTS" in r.get_json()["message"]
    doc = {"type": "FeatureCollection",
           "features": [{"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 1]}}] * 5}
    r = api.post("/api/waypoints/geojson", json=doc)
    assert r.status_code == 409 and r.get_json()["error"] == "too_many_waypoints"
    assert len(stored_rows(db_path(wp_app))) == 4


@pytest.mark.parametrize("body, fragment", [
    ({"type": "FeatureCollection",
      "features": [{"type": "Feature", "geometry": {"type": "Point", "coordinates": [1, 95]}}]},
     "features[0].geometry.coordinates[1] (lat)"),
    ({"type": "FeatureCollection",
      "features": [{"type": "Feature", "geometry": {"type": "Polygon", "coordinates": []}}]},
     "must be a Point"),
    ({"type": "Topology"}, "FeatureCollection"),
    ({"type": "FeatureCollection", "features": "all of them"}, "'features'"),
])
def test_malformed_geojson_import_changes_nothing(api, wp_app, body, fragment):
    add(api, 5.0, 5.0, "keep me")
    before = mission(api)
    r = api.post("/api/waypoints/geojson", json=body)
    assert r.status_code == 400 and fragment in r.get_json()["message"]
    assert mission(api) == before


@pytest.mark.parametrize("path, body, status", [
    ("/api/waypoints/1", {}, 400),
    ("/api/waypoints/1", {"index": -1}, 400),
    ("/api/waypoints/1", {"index": 1.5}, 400),
    ("/api/waypoints/1", {"lng": 200}, 400),
    ("/api/waypoints/1", {"position": 2}, 400),
    ("/api/waypoints/99999999999999999999999", {"lng": 1}, 404),
    ("/api/waypoints/abc", {"lng": 1}, 404),
])
def test_bad_patches(api, path, body, status):
    add(api, 5.0, 5.0)
    before = mission(api)
    r = api.patch(path, json=body)
    assert r.status_code == status and r.is_json and r.get_json()["error"]
    assert mission(api) == before


def test_schema_has_the_documented_checks(wp_app, api):
    add(api, 1.0, 1.0)
    conn = sqlite3.connect(db_path(wp_app))
    try:
        assert conn.execute("PRAGMA journal_mode").fetchone()[0] == "wal"
        ddl = conn.execute("SELECT sql FROM sqlite_master WHERE name = 'waypoints'").fetchone()[0]
    finally:
        conn.close()
    assert "lat BETWEEN -90.0 AND 90.0" in ddl and "lng BETWEEN -180.0 AND 180.0" in ddl and "UNIQUE" in ddl


def test_a_write_during_shutdown_is_503_not_a_crash(wp_app, api):
    wp_app.extensions["rover_web"].feature(WaypointsService).store.close()  # what shutdown does first
    r = api.post("/waypoints", json={"lng": 1.0, "lat": 2.0})
    assert r.status_code == 503 and r.get_json()["error"] == "shutting_down"
    assert stored_rows(db_path(wp_app)) == []
