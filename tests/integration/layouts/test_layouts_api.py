"""Layouts over REST with the app's real SQLite file: defaults, validation, roles, choices, fleets."""

import json
import sqlite3

import pytest

from rover_web.layouts.schema import MAX_CARDS, NAME_MAX
from tests.support.auth import sign_in

BOAT = {"version": 1, "name": "Crew boat", "cards": [
    {"type": "camera", "x": 0, "y": 0, "w": 8, "h": 6, "settings": {"topic": "/camera/image_raw"}},
    {"type": "gps_map", "x": 0, "y": 6, "w": 8, "h": 6},
    {"type": "scan_the_code", "x": 8, "y": 0, "w": 4, "h": 6},
    {"type": "drive", "x": 8, "y": 6, "w": 4, "h": 6}]}


def changed(doc, path, value):
    """A copy of `doc` with the value at `path` (keys and list indexes) replaced."""
    doc = json.loads(json.dumps(doc))
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return doc


def rows(db_path) -> list[tuple]:
    with sqlite3.connect(db_path) as conn:
        return conn.execute("SELECT id, name, body FROM layouts ORDER BY id").fetchall()


def test_the_first_start_creates_a_default_per_robot_kind_and_the_robots_own_is_active(client):
    listing = client.get("/api/layouts").get_json()
    assert [(x["name"], x["kind"]) for x in listing["layouts"]] == [
        ("Boat", "boat"), ("Rover", "rover"), ("Drone", "drone"), ("Everything", "robot")]
    assert listing["kind"] == "robot"
    everything = listing["layouts"][3]["id"]
    assert listing["active"] == everything
    mine = client.get("/api/me/layout").get_json()
    assert mine["id"] == everything and mine["layout"]["name"] == "Everything"


def test_export_and_import_round_trip_with_the_same_shape(client, app):
    created = client.post("/api/layouts", json=BOAT)
    assert created.status_code == 201, created.get_json()
    layout_id = created.get_json()["id"]
    exported = client.get(f"/api/layouts/{layout_id}?download=1")
    assert "attachment" in exported.headers["Content-Disposition"]
    doc = exported.get_json()
    assert doc["name"] == "Crew boat" and [c["type"] for c in doc["cards"]] == [c["type"] for c in BOAT["cards"]]
    assert doc["cards"][1]["settings"] == {}  # settings always present once stored
    again = client.post("/api/layouts", json={**doc, "name": "Crew boat 2"})
    assert again.status_code == 201
    assert client.get(f"/api/layouts/{again.get_json()['id']}").get_json() == {**doc, "name": "Crew boat 2"}
    assert client.post("/api/layouts", json=doc).status_code == 409  # the name is taken, any case
    assert client.post("/api/layouts", json={**doc, "name": "CREW BOAT"}).get_json()["error"] == "name_taken"


too_many = {**BOAT, "cards": [{"type": "plot", "x": i % 12, "y": i // 12, "w": 1, "h": 1,
                               "settings": {"series": [{"topic": "/odom", "field": "pose.pose.position.x"}]}}
                              for i in range(MAX_CARDS + 1)]}
BAD = [
    ("unknown card type", changed(BOAT, ["cards", 1, "type"], "toaster"), "cards[1].type", "bad_value"),
    ("unknown setting", changed(BOAT, ["cards", 0, "settings"], {"colour": "red"}), "cards[0].settings",
     "unknown_field"),
    ("bad topic", changed(BOAT, ["cards", 0, "settings", "topic"], "no spaces allowed"), "cards[0].settings.topic",
     "bad_value"),
    ("a topic ending in a newline", changed(BOAT, ["cards", 0, "settings", "topic"], "/a\n"),
     "cards[0].settings.topic", "bad_value"),  # `$` matched before it: stored, then the card failed
    ("a plot field ending in a newline",
     {**BOAT, "cards": [{"type": "plot", "x": 0, "y": 0, "w": 4, "h": 4,
                         "settings": {"series": [{"topic": "/odom", "field": "pose.x\n"}]}}]},
     "cards[0].settings.series[0].field", "bad_value"),
    ("plot without series", {**BOAT, "cards": [{"type": "plot", "x": 0, "y": 0, "w": 4, "h": 4, "settings": {}}]},
     "cards[0].settings.series", "missing_field"),
    ("overlap", changed(BOAT, ["cards", 3, "x"], 7), "cards[3]", "overlap"),
    ("out of the grid", changed(BOAT, ["cards", 2, "w"], 5), "cards[2].w", "out_of_grid"),
    ("negative x", changed(BOAT, ["cards", 2, "x"], -1), "cards[2].x", "out_of_range"),
    ("a width that is not a number", changed(BOAT, ["cards", 2, "w"], "4"), "cards[2].w", "bad_type"),
    ("a boolean width", changed(BOAT, ["cards", 2, "w"], True), "cards[2].w", "bad_type"),
    ("a fractional height", changed(BOAT, ["cards", 2, "h"], 2.5), "cards[2].h", "bad_type"),
    ("too many cards", too_many, "cards", "too_many"),
    ("a name too long", {**BOAT, "name": "n" * (NAME_MAX + 1)}, "name", "too_long"),
    ("a blank name", {**BOAT, "name": "   "}, "name", "bad_value"),
    ("a control character in the name", {**BOAT, "name": "tab\there"}, "name", "bad_value"),
    ("a lone surrogate in the name", {**BOAT, "name": "boat \ud800"}, "name", "bad_value"),  # SQLite cannot hold it
    ("no name", {k: v for k, v in BOAT.items() if k != "name"}, "name", "missing_field"),
    ("another version", {**BOAT, "version": 2}, "version", "bad_version"),
    ("an unknown field", {**BOAT, "theme": "dark"}, "", "unknown_field"),
    ("two cameras", changed(BOAT, ["cards", 3], {"type": "camera", "x": 8, "y": 6, "w": 4, "h": 6}),
     "cards[3].type", "duplicate_card"),
]


@pytest.mark.parametrize("what,doc,field,code", BAD, ids=[b[0] for b in BAD])
def test_a_bad_layout_is_a_400_naming_the_field_and_nothing_is_saved(client, app, what, doc, field, code):
    db_path = app.config["ROVER_WEB_DB_PATH"]
    target = client.post("/api/layouts", json={**BOAT, "name": "target"}).get_json()["id"]
    before = rows(db_path)
    for method, url in (("POST", "/api/layouts"), ("PUT", f"/api/layouts/{target}")):
        response = client.open(url, method=method, json=doc)
        body = response.get_json()
        assert response.status_code == 400, (method, body)
        assert (body["field"], body["error"]) == (field, code), body
        assert field in body["message"]
    assert rows(db_path) == before


def test_non_finite_numbers_and_non_objects_are_refused(client):
    raw = json.dumps(BOAT).replace('"w": 8', '"w": NaN', 1)
    response = client.post("/api/layouts", data=raw, content_type="application/json")
    assert response.status_code == 400 and response.get_json()["error"] == "non_finite"
    assert client.post("/api/layouts", json=[1, 2]).status_code == 400


def test_replace_delete_and_not_found(client):
    layout_id = client.post("/api/layouts", json=BOAT).get_json()["id"]
    replaced = client.put(f"/api/layouts/{layout_id}", json={**BOAT, "name": "Renamed", "cards": BOAT["cards"][:1]})
    assert replaced.status_code == 200
    assert client.get(f"/api/layouts/{layout_id}").get_json()["name"] == "Renamed"
    assert client.put(f"/api/layouts/{layout_id}", json={**BOAT, "name": "Boat"}).status_code == 409  # a default's
    assert client.delete(f"/api/layouts/{layout_id}").get_json() == {"deleted": layout_id}
    huge = 10**30  # more than SQLite's integers hold
    for response in (client.get(f"/api/layouts/{layout_id}"), client.delete(f"/api/layouts/{layout_id}"),
                     client.put(f"/api/layouts/{layout_id}", json=BOAT),
                     client.put("/api/me/layout", json={"id": layout_id}),
                     client.get(f"/api/layouts/{huge}"), client.delete(f"/api/layouts/{huge}"),
                     client.put(f"/api/layouts/{huge}", json=BOAT), client.put("/api/me/layout", json={"id": huge}),
                     client.put("/api/me/layout", json={"id": -1})):
        assert response.status_code == 404 and response.get_json()["error"] == "not_found"


@pytest.mark.parametrize("body,code", [({}, "missing_field"), ({"id": "1"}, "bad_type"), ({"id": True}, "bad_type"),
                                       ({"id": 1, "x": 2}, "unknown_field")])
def test_choosing_needs_a_layout_id(client, body, code):
    response = client.put("/api/me/layout", json=body)
    assert response.status_code == 400 and response.get_json()["error"] == code


def test_with_sign_in_off_one_choice_serves_every_browser_and_deleting_it_falls_back(app):
    first, second = app.test_client(), app.test_client()
    drone = next(x["id"] for x in first.get("/api/layouts").get_json()["layouts"] if x["name"] == "Drone")
    assert first.put("/api/me/layout", json={"id": drone}).get_json() == {"id": drone, "user": None}
    assert second.get("/api/me/layout").get_json()["id"] == drone
    assert second.get("/api/layouts").get_json()["active"] == drone
    first.delete(f"/api/layouts/{drone}")
    assert second.get("/api/me/layout").get_json()["layout"]["name"] == "Everything"


def test_roles_viewers_read_and_choose_operators_change(signed_app):
    tokens = signed_app.tokens
    client = signed_app.test_client()

    def call(role, method, url, body=None):
        headers = {"Authorization": f"Bearer {tokens[role]}"}
        return client.open(url, method=method, json=body, headers=headers)

    layouts = call("viewer", "GET", "/api/layouts").get_json()["layouts"]
    boat, rover = (next(x["id"] for x in layouts if x["name"] == n) for n in ("Boat", "Rover"))
    assert call("viewer", "GET", f"/api/layouts/{boat}").status_code == 200
    for method, url, body in (("POST", "/api/layouts", BOAT), ("PUT", f"/api/layouts/{boat}", BOAT),
                              ("DELETE", f"/api/layouts/{boat}", None)):
        refused = call("viewer", method, url, body)
        assert refused.status_code == 403 and refused.get_json()["error"] == "forbidden"
    assert call("operator", "POST", "/api/layouts", BOAT).status_code == 201
    assert client.get("/api/layouts").status_code == 401
    # Each user's choice is their own, and remembered.
    assert call("viewer", "PUT", "/api/me/layout", {"id": boat}).get_json() == {"id": boat, "user": "viewer"}
    assert call("operator", "PUT", "/api/me/layout", {"id": rover}).status_code == 200
    assert call("viewer", "GET", "/api/me/layout").get_json()["layout"]["name"] == "Boat"
    assert call("operator", "GET", "/api/me/layout").get_json()["layout"]["name"] == "Rover"
    assert call("admin", "GET", "/api/me/layout").get_json()["layout"]["name"] == "Everything"
    # Signed in through the form too: the page's own session.
    browser = signed_app.test_client()
    sign_in(browser, "viewer")
    assert browser.get("/api/me/layout").get_json()["layout"]["name"] == "Boat"


def test_choices_and_layouts_survive_a_restart_and_the_defaults_are_not_made_again(app_factory, tmp_path):
    db = str(tmp_path / "kept.sqlite3")
    first = app_factory(ROVER_WEB_DB_PATH=db)
    client = first.test_client()
    layouts = client.get("/api/layouts").get_json()["layouts"]
    boat = next(x["id"] for x in layouts if x["name"] == "Boat")
    client.delete(f"/api/layouts/{next(x['id'] for x in layouts if x['name'] == 'Rover')}")
    made = client.post("/api/layouts", json=BOAT).get_json()["id"]
    client.put("/api/me/layout", json={"id": made})
    first.extensions["rover_web"].shutdown()
    second = app_factory(ROVER_WEB_DB_PATH=db).test_client()
    assert [x["name"] for x in second.get("/api/layouts").get_json()["layouts"]] == \
        ["Boat", "Drone", "Everything", "Crew boat"]
    assert second.get("/api/me/layout").get_json()["id"] == made
    assert boat in [x["id"] for x in second.get("/api/layouts").get_json()["layouts"]]
    with sqlite3.connect(db) as conn:
        assert conn.execute("SELECT version FROM schema_versions WHERE package = 'layouts'").fetchone() == (2,)


def test_a_database_from_a_newer_rover_web_is_refused_at_start(app_factory, tmp_path):
    from rover_web.config import ConfigError

    db = str(tmp_path / "newer.sqlite3")
    app_factory(ROVER_WEB_DB_PATH=db).extensions["rover_web"].shutdown()
    with sqlite3.connect(db) as conn:
        conn.execute("UPDATE schema_versions SET version = 99 WHERE package = 'layouts'")
    with pytest.raises(ConfigError, match="layouts tables are at version 99"):
        app_factory(ROVER_WEB_DB_PATH=db)


def test_each_robot_of_a_fleet_has_its_own_layouts(app_factory):
    app = app_factory(ROVER_WEB_ROBOTS=[{"name": "boat"}, {"name": "drone"}])
    client = app.test_client()
    assert client.get("/robots/boat/api/me/layout").get_json()["layout"]["name"] == "Boat"
    assert client.get("/robots/drone/api/me/layout").get_json()["layout"]["name"] == "Drone"
    assert client.get("/api/me/layout").get_json()["layout"]["name"] == "Boat"  # the root is the first robot's
    made = client.post("/robots/drone/api/layouts", json=BOAT).get_json()["id"]
    names = {r: [x["name"] for x in client.get(f"/robots/{r}/api/layouts").get_json()["layouts"]]
             for r in ("boat", "drone")}
    assert "Crew boat" in names["drone"] and "Crew boat" not in names["boat"]
    client.put("/robots/drone/api/me/layout", json={"id": made})
    assert client.get("/robots/drone/api/me/layout").get_json()["layout"]["name"] == "Crew boat"
    assert client.get("/robots/boat/api/me/layout").get_json()["layout"]["name"] == "Boat"
