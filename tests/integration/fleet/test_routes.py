"""Issue 20: /api/robots, /robots/<name>/... for a robot that does not exist, a malformed
ROVER_WEB_ROBOTS, each robot's own database and event stream."""

import pytest

from rover_web.config import ConfigError

from .helpers import ROBOTS, get, post


@pytest.fixture
def fleet_client(app_factory):
    return app_factory(ROVER_WEB_ROBOTS=ROBOTS).test_client()


def test_api_robots_lists_both_with_namespaces_and_urls(fleet_client):
    listed = fleet_client.get("/api/robots").json
    assert listed["current"] == "boat"  # the root routes are the first robot's
    assert [(r["name"], r["namespace"], r["kind"], r["url"]) for r in listed["robots"]] == [
        ("boat", "/boat", "boat", "/robots/boat/"), ("drone", "/drone", "drone", "/robots/drone/")]
    assert all(r["link"] == "no_data" and r["mode"] == "idle" and r["estop"]["engaged"] is False
               for r in listed["robots"])
    assert fleet_client.get("/robots/drone/api/robots").json["current"] == "drone"
    for robot in listed["robots"]:  # every listed URL serves that robot
        assert fleet_client.get(robot["url"] + "api/robots").json["current"] == robot["name"]


@pytest.mark.parametrize("method, path", [("GET", "/robots/nope/api/status"), ("GET", "/robots/nope/api/robots"),
                                          ("POST", "/robots/nope/api/teleop"), ("POST", "/robots/nope/api/estop"),
                                          ("GET", "/robots/Boat/api/status")])
def test_an_unknown_robot_is_a_json_404(fleet_client, method, path):
    response = fleet_client.open(path, method=method, json={"command": "forward"} if method == "POST" else None)
    assert response.status_code == 404, response.data[:200]
    assert response.is_json and response.json["error"] == "not_found" and response.json["message"]
    for name in ("boat", "drone"):  # nothing was driven or stopped
        assert fleet_client.get(f"/robots/{name}/api/teleop").json["source"] is None
        assert fleet_client.get(f"/robots/{name}/api/estop").json["engaged"] is False


@pytest.mark.parametrize("robots, why", [
    ([{"name": "boat"}, {"name": "boat"}], "two robots have the name"),
    ([{"name": "boat"}, {"name": "drone", "namespace": "/boat"}], "two robots have the namespace"),
    ([{"name": "Boat"}], "name"),
    ([{"name": "2boat"}], "name"),
    ([{"name": "bo-at"}], "name"),
    ([{"name": ""}], "name"),
    ([{"namespace": "/boat"}], "name"),
    ([{"name": "boat", "namespace": "boat"}], "namespace"),
    ([{"name": "boat", "namespace": "/boat/"}], "namespace"),
    ([{"name": "boat", "namespace": "/1boat"}], "namespace"),
    ([{"name": "boat", "namespace": "/bo at"}], "namespace"),
    ([{"name": "boat", "speed": 3}], "unknown field"),
    ([{"name": "boat", "kind": "submarine"}], "kind"),
    ([{"name": "boat", "title": 5}], "title"),
    ([["boat"]], "expected an object"),
    ({"name": "boat"}, "expected a list"),
])
def test_a_malformed_robots_setting_stops_create_app(app_factory, robots, why):
    with pytest.raises(ConfigError, match="ROVER_WEB_ROBOTS") as raised:
        app_factory(ROVER_WEB_ROBOTS=robots)
    assert why in str(raised.value)


@pytest.mark.parametrize("text, why", [("boat,boat", "two robots have the name"), ("boat,Drone", "name"),
                                       ('[{"name": "boat", "ns": "/b"}]', "unknown field"),
                                       ('[{"name": "boat"', "ROVER_WEB_ROBOTS")])
def test_a_malformed_robots_variable_stops_create_app(app_factory, monkeypatch, text, why):
    monkeypatch.setenv("ROVER_WEB_ROBOTS", text)
    with pytest.raises(ConfigError, match="ROVER_WEB_ROBOTS") as raised:
        app_factory()
    assert why in str(raised.value)


def test_the_short_form_in_the_environment_names_the_robots(app_factory, monkeypatch):
    monkeypatch.setenv("ROVER_WEB_ROBOTS", "boat, drone_a ,rover2")
    listed = app_factory().test_client().get("/api/robots").json["robots"]
    assert [(r["name"], r["namespace"], r["kind"]) for r in listed] == [
        ("boat", "/boat", "boat"), ("drone_a", "/drone_a", "drone"), ("rover2", "/rover2", "rover")]


def test_each_robot_keeps_its_latch_in_its_own_database(app_factory, tmp_path):
    db = str(tmp_path / "fleet.sqlite3")
    first = app_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_DB_PATH=db)
    assert first.test_client().post("/robots/drone/api/estop", json={"engaged": True, "by": "pilot"}).json["engaged"]
    first.extensions["rover_web"].shutdown()
    assert (tmp_path / "fleet-drone.sqlite3").exists() and not (tmp_path / "fleet-boat.sqlite3").exists()

    again = app_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_DB_PATH=db).test_client()
    assert again.get("/robots/drone/api/estop").json["engaged"] is True
    assert again.get("/robots/drone/api/estop").json["by"] == "pilot"
    assert again.get("/robots/boat/api/estop").json["engaged"] is False
    assert again.post("/robots/boat/api/teleop", json={"command": "stop"}).status_code == 200
    assert again.post("/robots/drone/api/teleop", json={"command": "forward"}).status_code == 409


def test_each_robot_s_event_stream_has_its_own_latch(fleet_server, sse_client):
    server = fleet_server()
    streams = {name: sse_client(f"{url}/api/events?channels=estop") for name, url in server.robot.items()}
    for stream in streams.values():
        assert stream.wait_for("estop")["json"]["engaged"] is False  # the snapshot
    assert post(server.robot["drone"] + "/api/estop", {"engaged": True, "by": "pilot"}).status_code == 200
    assert streams["drone"].wait_for("estop", lambda s: s["engaged"])["json"]["by"] == "pilot"
    assert post(server.robot["boat"] + "/api/estop", {"engaged": True, "by": "deckhand"}).status_code == 200
    assert streams["boat"].wait_for("estop", lambda s: s["engaged"])["json"]["by"] == "deckhand"
    # The boat's stream went from its snapshot to its own engage: the drone's came and went unseen.
    assert latches(streams["boat"]) == [(False, None), (True, "deckhand")]
    assert post(server.robot["drone"] + "/api/estop", {"engaged": False}).status_code == 200
    streams["drone"].wait_for("estop", lambda s: not s["engaged"])
    assert get(server.robot["boat"] + "/api/estop")["engaged"] is True
    assert latches(streams["drone"])[:2] == [(False, None), (True, "pilot")]
    assert [engaged for engaged, _ in latches(streams["drone"])] == [False, True, False]
    assert latches(streams["boat"]) == [(False, None), (True, "deckhand")]


def latches(stream) -> list[tuple[bool, str | None]]:
    """(engaged, by) of each change on the estop channel (an engage is sent again with its goal
    cancels' outcome: the same latch)."""
    out = []
    for event in stream.of("estop"):
        latch = (event["json"]["engaged"], event["json"]["by"])
        if not out or out[-1] != latch:
            out.append(latch)
    return out


def test_sign_in_and_roles_hold_under_every_robot_s_prefix(app_factory, tmp_path):
    from tests.support.auth import add_users

    db = tmp_path / "signed.sqlite3"
    tokens = add_users(db)  # the users live in the first robot's database, for every robot
    client = app_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db)).test_client()

    def as_(role):
        return {"Authorization": f"Bearer {tokens[role]}"} if role else {}

    for robot in ("boat", "drone"):
        drive = f"/robots/{robot}/api/teleop"
        assert client.post(drive, json={"command": "stop"}, headers=as_(None)).status_code == 401
        assert client.post(drive, json={"command": "stop"}, headers=as_("viewer")).status_code == 403
        assert client.post(drive, json={"command": "stop"}, headers=as_("operator")).status_code == 200
        assert client.get(f"/robots/{robot}/api/status", headers=as_(None)).status_code == 401
        assert client.get(f"/robots/{robot}/api/status", headers=as_("viewer")).status_code == 200
    # Any signed-in user stops every robot; releasing one takes an operator.
    assert client.post("/api/estop/all", json={}, headers=as_(None)).status_code == 401
    stopped = client.post("/api/estop/all", json={}, headers=as_("viewer"))
    assert stopped.status_code == 200 and all(s["by"] == "viewer" for s in stopped.json["robots"].values())
    release = {"engaged": False}
    assert client.post("/robots/drone/api/estop", json=release, headers=as_("viewer")).status_code == 403
    assert client.post("/robots/drone/api/estop", json=release, headers=as_("operator")).json["engaged"] is False
    assert client.get("/robots/boat/api/estop", headers=as_("viewer")).json["engaged"] is True


def test_signing_in_from_a_robot_s_page_comes_back_to_that_robot(app_factory, tmp_path):
    from tests.support.auth import PASSWORD, add_users

    db = tmp_path / "signed.sqlite3"
    add_users(db, "operator")
    client = app_factory(ROVER_WEB_ROBOTS=ROBOTS, ROVER_WEB_AUTH="required", ROVER_WEB_DB_PATH=str(db)).test_client()
    page = client.get("/robots/drone/livemap")
    assert page.status_code == 302
    assert page.headers["Location"] == "/robots/drone/login?next=/robots/drone/livemap"
    form = client.get(page.headers["Location"])
    assert b'value="/robots/drone/livemap"' in form.data
    signed = client.post("/robots/drone/login", data={"username": "operator", "password": PASSWORD,
                                                      "next": "/robots/drone/livemap"})
    assert signed.status_code == 303 and signed.headers["Location"] == "/robots/drone/livemap"
    # No next: back to the robot's own dashboard, not the first robot's.
    client.post("/robots/drone/logout")
    signed = client.post("/robots/drone/login", data={"username": "operator", "password": PASSWORD})
    assert signed.headers["Location"] == "/robots/drone/"
