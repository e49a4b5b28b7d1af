"""GET/PUT /api/geofence on a real app (real SQLite), and every waypoint path it refuses."""

import json
import sqlite3

import pytest

from rover_web.config import ConfigError
from tests.support.geofence_helpers import FENCE, IN_KEEP_OUT, INSIDE, OUTSIDE, area, collection, square
from tests.support.waypoint_helpers import stored_rows


@pytest.fixture
def gf_app(app_factory, tmp_path):
    return app_factory(ROVER_WEB_MAP_TILES=str(tmp_path / "no-tiles"), ROVER_WEB_GEOFENCE_MAX_VERTICES=40)


@pytest.fixture
def api(gf_app):
    client = gf_app.test_client()
    assert client.put("/api/geofence", json=FENCE).status_code == 200
    return client


def stored_fence(app):
    conn = sqlite3.connect(app.config["ROVER_WEB_DB_PATH"])
    try:
        row = conn.execute("SELECT doc, revision FROM geofence").fetchone()
        return (json.loads(row[0]), row[1]) if row else None
    finally:
        conn.close()


def test_no_fence_at_first_then_put_replaces_it_and_it_is_on_disk(gf_app):
    client = gf_app.test_client()
    assert client.get("/api/geofence").get_json() == {"type": "FeatureCollection", "features": [], "revision": 0}
    r = client.put("/api/geofence", json=FENCE)
    assert r.status_code == 200
    body = r.get_json()
    assert body["revision"] == 1 and [f["properties"] for f in body["features"]] == \
        [{"kind": "keep_in", "name": "lake"}, {"kind": "keep_out", "name": "dock"}]
    assert client.get("/api/geofence").get_json() == body
    doc, revision = stored_fence(gf_app)
    assert revision == 1 and doc["features"] == body["features"]
    smaller = collection(area("keep_in", square(0, 0, 0.5, 0.5)))
    assert client.put("/api/geofence", json=smaller).get_json()["revision"] == 2
    assert len(stored_fence(gf_app)[0]["features"]) == 1


def test_the_fence_survives_a_restart(app_factory, tmp_path):
    db = str(tmp_path / "kept.sqlite3")
    first = app_factory(ROVER_WEB_DB_PATH=db)
    first.test_client().put("/api/geofence", json=FENCE)
    first.extensions["rover_web"].shutdown()  # one server per database: the next one is a restart
    again = app_factory(ROVER_WEB_DB_PATH=db).test_client()
    fence = again.get("/api/geofence").get_json()
    assert fence["revision"] == 1 and len(fence["features"]) == 2
    assert again.post("/api/waypoints", json={"lng": OUTSIDE[0], "lat": OUTSIDE[1]}).status_code == 422


@pytest.mark.parametrize("doc, code, words", [
    ({"type": "FeatureCollection", "features": [area("keep_out", [[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]],
                                                        name="bowtie")]},
     "invalid_geometry", "features[0] ('bowtie')"),
    (collection(area("keep_in", [[i / 100, 0] for i in range(45)] + [[0.1, 1], [0, 0]])), "too_many_vertices",
     "ROVER_WEB_GEOFENCE_MAX_VERTICES"),
    (collection(area("keep_in", [[179, 0], [-179, 0], [-179, 1], [179, 1], [179, 0]])), "antimeridian",
     "antimeridian"),
    ({"type": "Feature"}, "bad_geojson", "FeatureCollection"),
    (collection({"type": "Feature", "properties": {}, "geometry": None}), "bad_geojson", "kind"),
])
def test_an_invalid_fence_is_400_and_nothing_changes(api, gf_app, doc, code, words):
    before = stored_fence(gf_app)
    r = api.put("/api/geofence", json=doc)
    assert r.status_code == 400
    assert r.get_json()["error"] == code and words in r.get_json()["message"]
    assert stored_fence(gf_app) == before
    assert api.get("/api/geofence").get_json()["revision"] == before[1]


def test_put_bodies_that_are_not_json_are_refused(api):
    assert api.put("/api/geofence", data="{", content_type="application/json").status_code == 400
    assert api.put("/api/geofence", data="x", content_type="text/plain").status_code == 415


@pytest.mark.parametrize("route", ["/api/waypoints", "/waypoints"])
@pytest.mark.parametrize("point, reason", [(OUTSIDE, "outside_keep_in"), (IN_KEEP_OUT, "inside_keep_out")])
def test_adds_outside_the_fence_are_422_and_not_stored(api, gf_app, route, point, reason):
    r = api.post(route, json={"lng": point[0], "lat": point[1]})
    assert r.status_code == 422
    body = r.get_json()
    assert body["error"] == "outside_geofence" and body["reason"] == reason
    assert (body["lng"], body["lat"]) == point and body["message"]
    assert stored_rows(gf_app.config["ROVER_WEB_DB_PATH"]) == []
    assert api.get("/api/waypoints").get_json()["revision"] == 0
    assert api.post(route, json={"lng": INSIDE[0], "lat": INSIDE[1]}).status_code in (200, 201)


def test_a_move_outside_is_422_and_the_waypoint_stays(api, gf_app):
    waypoint = api.post("/api/waypoints", json={"lng": 0.3, "lat": 0.3}).get_json()["waypoint"]
    r = api.patch(f"/api/waypoints/{waypoint['id']}", json={"lat": 0.7, "lng": 0.7, "label": "x"})
    assert r.status_code == 422 and r.get_json()["reason"] == "inside_keep_out"
    r = api.patch(f"/api/waypoints/{waypoint['id']}", json={"lng": 1.5})  # lat kept: (1.5, 0.3)
    assert r.status_code == 422 and r.get_json()["reason"] == "outside_keep_in"
    assert stored_rows(gf_app.config["ROVER_WEB_DB_PATH"]) == [(0, 0.3, 0.3, "")]
    assert api.patch(f"/api/waypoints/{waypoint['id']}", json={"label": "fine"}).status_code == 200
    assert api.patch(f"/api/waypoints/{waypoint['id']}", json={"lng": 0.9}).status_code == 200


def test_an_import_with_one_point_outside_changes_nothing(api, gf_app):
    api.post("/api/waypoints", json={"lng": 0.3, "lat": 0.3})
    doc = {"type": "FeatureCollection", "features": [
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [0.2, 0.2]}, "properties": {}},
        {"type": "Feature", "geometry": {"type": "Point", "coordinates": [2.0, 0.2]}, "properties": {}}]}
    r = api.post("/api/waypoints/geojson", json=doc)
    assert r.status_code == 422 and r.get_json()["waypoint"] == 1 and "features[1]" in r.get_json()["message"]
    assert stored_rows(gf_app.config["ROVER_WEB_DB_PATH"]) == [(0, 0.3, 0.3, "")]


def test_a_mission_with_a_waypoint_or_a_leg_outside_is_not_sent(api, gf_app):
    a = api.post("/api/waypoints", json={"lng": 0.5, "lat": 0.7}).get_json()["waypoint"]
    api.post("/api/waypoints", json={"lng": 0.9, "lat": 0.7})  # the leg a -> b crosses the dock
    r = api.post("/api/waypoints/send", json={})
    assert r.status_code == 422
    assert r.get_json()["reason"] == "leg_crosses_keep_out" and r.get_json()["leg"] == [0, 1]
    assert api.patch(f"/api/waypoints/{a['id']}", json={"lat": 0.9}).status_code == 200
    assert api.post("/api/waypoints/send", json={}).status_code == 422  # (0.5,0.9)->(0.9,0.7): still crosses
    api.patch(f"/api/waypoints/{a['id']}", json={"lat": 0.3})
    # Shrinking the fence makes a stored waypoint outside it: the send names it.
    api.put("/api/geofence", json=collection(area("keep_in", square(0, 0, 0.6, 1))))
    r = api.post("/api/waypoints/send", json={})
    assert r.status_code == 422 and r.get_json()["reason"] == "outside_keep_in" and r.get_json()["waypoint"] == 1


def test_an_empty_fence_allows_everything(api):
    api.put("/api/geofence", json=collection())
    assert api.post("/api/waypoints", json={"lng": OUTSIDE[0], "lat": OUTSIDE[1]}).status_code == 201


def test_the_geofence_file_seeds_only_an_empty_database(app_factory, tmp_path):
    path = tmp_path / "fence.geojson"
    path.write_text(json.dumps(FENCE))
    db = str(tmp_path / "seeded.sqlite3")
    first_app = app_factory(ROVER_WEB_DB_PATH=db, ROVER_WEB_GEOFENCE_FILE=str(path))
    first = first_app.test_client()
    assert first.get("/api/geofence").get_json()["revision"] == 1
    first.put("/api/geofence", json=collection())
    first_app.extensions["rover_web"].shutdown()
    again = app_factory(ROVER_WEB_DB_PATH=db, ROVER_WEB_GEOFENCE_FILE=str(path)).test_client()
    assert again.get("/api/geofence").get_json() == {"type": "FeatureCollection", "features": [], "revision": 2}


def test_a_broken_geofence_file_stops_the_start(app_factory, tmp_path):
    path = tmp_path / "fence.geojson"
    path.write_text(json.dumps(collection(area("keep_in", [[0, 0], [1, 1], [1, 0], [0, 1], [0, 0]]))))
    with pytest.raises(ConfigError, match="ROVER_WEB_GEOFENCE_FILE.*Self-intersection"):
        app_factory(ROVER_WEB_GEOFENCE_FILE=str(path))


def test_the_demo_fence_is_valid_and_holds_the_simulator_start():
    from rover_web.config import ROOT
    from rover_web.demo import DEMO_GEOFENCE
    from rover_web.geofence.rules import parse_fence
    from rover_web.sim.rover import BENDERSON_LAT, BENDERSON_LON

    fence = parse_fence(json.loads((ROOT / DEMO_GEOFENCE).read_text()), 2000)
    assert fence.allows(BENDERSON_LON, BENDERSON_LAT)
    assert not fence.allows(BENDERSON_LON + 0.02, BENDERSON_LAT)


def test_only_an_admin_replaces_or_empties_the_fence_and_the_operator_log_names_them(app_factory, tmp_path):
    """Issue 27: any operator could empty the fence (and with it every keep-out check), logged without a name."""
    from tests.support.auth import add_users

    db_path = tmp_path / "signed.sqlite3"
    tokens = add_users(db_path)
    app = app_factory(ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db_path),
                      ROVER_WEB_MAP_TILES=str(tmp_path / "no-tiles"), ROVER_WEB_GEOFENCE_MAX_VERTICES=40)
    client = app.test_client()
    as_ = {role: {"Authorization": f"Bearer {token}"} for role, token in tokens.items()}
    assert client.put("/api/geofence", json=FENCE, headers=as_["admin"]).status_code == 200
    empty = {"type": "FeatureCollection", "features": []}
    for role in ("viewer", "operator"):
        refused = client.put("/api/geofence", json=empty, headers=as_[role])
        assert refused.status_code == 403 and refused.get_json()["error"] == "forbidden", role
    assert stored_fence(app)[1] == 1  # unchanged
    assert client.put("/api/geofence", json=empty, headers=as_["admin"]).get_json()["revision"] == 2
    conn = sqlite3.connect(db_path)
    try:
        rows = conn.execute("SELECT control, label, client FROM panel_log WHERE panel = 'geofence' "
                            "ORDER BY id").fetchall()
    finally:
        conn.close()
    assert [(r[0], r[2]) for r in rows] == [("replace", "admin"), ("empty", "admin")]
    assert "revision 2, 0 areas" in rows[1][1]


def test_with_sign_in_off_the_operator_log_names_the_address(gf_app):
    client = gf_app.test_client()
    assert client.put("/api/geofence", json=FENCE).status_code == 200
    conn = sqlite3.connect(gf_app.config["ROVER_WEB_DB_PATH"])
    try:
        assert conn.execute("SELECT client FROM panel_log WHERE panel = 'geofence'").fetchall() == [("127.0.0.1",)]
    finally:
        conn.close()
