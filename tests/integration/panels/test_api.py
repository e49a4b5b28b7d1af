"""The panels API with real ROS peers: 404/400/409, nothing published on refusal, every scalar type,
the unlock timeout, staleness on SSE, the operator log in SQLite, and a bad panel file at start."""

import re
import time

import pytest
import requests

from rover_web.config import ConfigError
from tests.support.panels_support import JSON, STRING, display, feed_status, log_entries, post

INT8 = "std_msgs/msg/Int8"


def test_unknown_panel_or_control_is_404_and_not_logged(client):
    for method, path, code in [
        ("get", "/api/panels/nope", "unknown_panel"),
        ("get", "/api/panels/nope/log", "unknown_panel"),
        ("post", "/api/panels/nope/stop", "unknown_panel"),
        ("post", "/api/panels/nope/unlock", "unknown_panel"),
        ("post", "/api/panels/drone/launch", "unknown_control"),
        ("post", "/api/panels/drone/log", "unknown_control"),
    ]:
        response = getattr(client, method)(path, json={} if method == "post" else None)
        assert response.status_code == 404, path
        assert response.json["error"] == code, path
    assert "takeoff" in client.post("/api/panels/drone/launch", json={}).json["message"]
    assert client.get("/panels/nope").status_code == 404
    assert client.get("/api/panels/drone/log").json["entries"] == []
    assert client.get("/api/panels/drone/takeoff").status_code == 405
    assert client.get("/api/panels/drone/log?limit=0").status_code == 400
    assert client.get("/api/panels/drone/log?limit=x").json["error"] == "bad_limit"


def test_refused_commands_publish_nothing_and_are_logged(live_server, ros_peer):
    url = live_server.url
    drone = ros_peer("fake_drone")
    drone.advertise("/status", STRING)
    listener = ros_peer("listener")
    listener.subscribe("/control_phase", INT8)
    listener.subscribe("/flight_destination", INT8)
    listener.wait_match("/control_phase")
    listener.wait_match("/flight_destination")
    drone.wait_match("/status")
    feed_status(drone, url, "Hovering")

    locked = post(url, "drone/destination", {"value": 3, "confirmed": True})
    assert locked.status_code == 409 and locked.json()["error"] == "locked"
    assert post(url, "drone/unlock").status_code == 200

    bad_values = [
        ({"value": 200, "confirmed": True}, "out_of_range", "must be from 0 to 127"),
        ({"value": -129, "confirmed": True}, "out_of_range", "got -129"),
        ({"value": "3", "confirmed": True}, "bad_type", "must be an integer"),
        ({"value": 2.5, "confirmed": True}, "bad_type", "must be an integer"),
        ({"value": True, "confirmed": True}, "bad_type", "got true"),
        ({"confirmed": True}, "missing_field", "'value' is required"),
        ({"value": 3, "confirmed": True, "speed": 1}, "unknown_field", "speed"),
        ({"value": 3}, "confirmation_required", "confirmed"),
        ({"value": 3, "confirmed": "yes"}, "bad_type", "'confirmed'"),
    ]
    for body, code, words in bad_values:
        response = post(url, "drone/destination", body)
        assert response.status_code == 400, body
        assert response.json()["error"] == code, body
        assert words in response.json()["message"], response.json()
    for raw, code in [('{"value": NaN, "confirmed": true}', "non_finite"),
                      ('{"value": Infinity, "confirmed": true}', "non_finite"),
                      ('{"value": 1e400, "confirmed": true}', "non_finite"),
                      ('{"value": ', "bad_json"), ("[3]", "bad_json")]:
        response = requests.post(f"{url}/api/panels/drone/destination", data=raw, headers=JSON, timeout=10)
        assert response.status_code == 400 and response.json()["error"] == code, raw
    response = post(url, "drone/takeoff", {"value": 1, "confirmed": True})  # a button takes no value
    assert response.status_code == 400 and response.json()["error"] == "unknown_field"
    response = post(url, "drone/takeoff", {"confirmed": True})  # Hovering: not allowed
    assert response.status_code == 409 and response.json() == {
        "error": "not_allowed", "message": "Take off is only allowed when Status is Standby; it is Hovering"}

    sent = post(url, "drone/destination", {"value": 5, "confirmed": True})
    assert sent.status_code == 200 and sent.json()["value"] == 5 and sent.json()["topic"] == "/flight_destination"
    listener.wait_for("/flight_destination", lambda m: m["data"] == 5)
    time.sleep(0.5)
    assert [m["msg"]["data"] for m in listener.received("/flight_destination")] == [5]
    assert listener.received("/control_phase") == []

    results = [(e["control"], e["result"]) for e in reversed(log_entries(url))]
    assert results == ([("destination", "refused"), ("unlock", "unlocked")] + [("destination", "invalid")] * 14
                       + [("takeoff", "invalid"), ("takeoff", "refused"), ("destination", "sent")])
    entries = log_entries(url)
    assert entries[0]["value"] == 5 and entries[0]["client"] == "127.0.0.1"
    assert entries[1]["reason"] == "Take off is only allowed when Status is Standby; it is Hovering"
    assert any(e["value"] == 200 and "from 0 to 127" in e["reason"] for e in entries)


# type, a value at the edge of its range, a value it refuses
SCALARS = [
    ("Bool", True, 1), ("Byte", 255, 256), ("Char", 65, -1), ("Int8", -128, 128), ("UInt8", 255, -1),
    ("Int16", -32768, 32768), ("UInt16", 65535, 65536), ("Int32", -2**31, 2**31), ("UInt32", 2**32 - 1, -1),
    ("Int64", -2**63, 2**63), ("UInt64", 2**64 - 1, 2**64), ("Float32", 0.25, 1e39), ("Float64", -1e300, "1.0"),
    ("String", "héllo", 5),
]


def scalar_panel(tmp_path) -> str:
    controls = [f'[panels.types.controls.{short.lower()}]\nkind = "input"\nlabel = "{short}"\n'
                f'topic = "/t_{short.lower()}"\ntype = "std_msgs/{short}"\n' for short, _good, _bad in SCALARS]
    path = tmp_path / "types.toml"
    path.write_text("[panels.types]\nunlock_timeout_s = 600\n\n" + "\n".join(controls))
    return str(path)


def test_every_std_msgs_scalar_is_published_with_its_type_and_range(live_server_factory, ros_peer, tmp_path):
    server = live_server_factory(ROVER_WEB_PANELS_FILE=scalar_panel(tmp_path))
    url = server.url
    peer = ros_peer()
    for short, _good, _bad in SCALARS:
        peer.subscribe(f"/t_{short.lower()}", f"std_msgs/msg/{short}")
    for short, _good, _bad in SCALARS:
        peer.wait_match(f"/t_{short.lower()}")
    assert post(url, "types/unlock").status_code == 200
    for short, _good, bad in SCALARS:
        response = post(url, f"types/{short.lower()}", {"value": bad})
        assert response.status_code == 400, (short, bad, response.json())
    for short, good, _bad in SCALARS:
        response = post(url, f"types/{short.lower()}", {"value": good})
        assert response.status_code == 200, (short, response.json())
    for short, good, _bad in SCALARS:
        message = peer.wait_for(f"/t_{short.lower()}")
        assert message["msg"]["data"] in (good, [good]), short  # a Byte may read back as a one-octet list
    time.sleep(0.3)
    assert all(len(peer.received(f"/t_{short.lower()}")) == 1 for short, _g, _b in SCALARS)  # no refusal went out


def short_timeout_panel(tmp_path, unlock_timeout_s=1.0, stale_after_s=0.5) -> str:
    path = tmp_path / "rig.toml"
    path.write_text(f"""
[panels.rig]
unlock_timeout_s = {unlock_timeout_s}
stale_after_s = {stale_after_s}
light = {{ display = "status", idle = ["Standby"] }}
[panels.rig.displays.status]
label = "Status"
topic = "/status"
type = "std_msgs/String"
[panels.rig.controls.beep]
kind = "button"
label = "Beep"
topic = "/beep"
type = "std_msgs/Bool"
value = true
""")
    return str(path)


def test_unlock_relocks_after_inactivity_and_commands_renew_it(live_server_factory, tmp_path, sse_client):
    server = live_server_factory(ROVER_WEB_PANELS_FILE=short_timeout_panel(tmp_path, unlock_timeout_s=1.0))
    url = server.url
    stream = sse_client(url + "/api/events?channels=panel,panel_log")
    stream.wait_for("panel", lambda d: d["panels"]["rig"]["locked"] is True)
    assert post(url, "rig/beep").json()["error"] == "locked"
    unlocked_at = time.monotonic()
    assert post(url, "rig/unlock").json()["locked"] is False
    stream.wait_for("panel", lambda d: d["panels"]["rig"]["locked"] is False
                    and d["panels"]["rig"]["controls"]["beep"]["enabled"])
    time.sleep(0.6)
    assert post(url, "rig/beep").status_code == 200  # renews: locked no earlier than 1 s from now
    time.sleep(0.6)
    assert time.monotonic() - unlocked_at > 1.0
    assert post(url, "rig/beep").status_code == 200
    last_command = time.monotonic()
    event = stream.wait_for("panel_log", lambda e: e["result"] == "locked", timeout=5)
    assert event["t"] - last_command >= 0.9  # not before the timeout
    assert event["json"]["reason"] == "no command for 1 s"
    stream.wait_for("panel", lambda d: d["panels"]["rig"]["locked"] is True)
    response = post(url, "rig/beep")
    assert response.status_code == 409 and response.json()["error"] == "locked"
    assert post(url, "rig/lock").json()["log"] is None  # already locked: nothing to log
    results = [e["result"] for e in reversed(log_entries(url, "rig"))]
    assert results == ["refused", "unlocked", "sent", "sent", "locked", "refused"]


def test_displays_stream_on_sse_and_go_stale(live_server_factory, tmp_path, ros_peer, sse_client):
    server = live_server_factory(ROVER_WEB_PANELS_FILE=short_timeout_panel(tmp_path, stale_after_s=0.5))
    url = server.url
    stream = sse_client(url + "/api/events?channels=panel")
    peer = ros_peer()
    peer.advertise("/status", STRING)
    peer.wait_match("/status")
    feed_status(peer, url, "Flying", panel="rig")
    event = stream.wait_for("panel", lambda d: d["panels"]["rig"]["displays"]["status"]["value"] == "Flying")
    assert event["json"]["panels"]["rig"]["displays"]["status"] == {"value": "Flying", "text": "Flying", "fresh": True}
    assert event["json"]["panels"]["rig"]["light"] == "red"
    silent_from = time.monotonic()
    stale = stream.wait_for("panel", lambda d: d["panels"]["rig"]["displays"]["status"] == {
        "value": "Flying", "text": "Flying", "fresh": False})
    assert stale["t"] - silent_from >= 0.4
    assert stale["json"]["panels"]["rig"]["light"] == "unknown"
    shown = display(url, "rig", "status")
    assert shown["value"] == "Flying" and shown["fresh"] is False and shown["age_s"] >= 0.5
    status = requests.get(url + "/api/status", timeout=5).json()
    assert any(t["topic"] == "/status" and t["type"] == STRING for t in status["topics"])
    feed_status(peer, url, "Standby", panel="rig")
    stream.wait_for("panel", lambda d: d["panels"]["rig"]["light"] == "green")


def test_operator_log_persists_in_sqlite_and_the_page_shows_the_newest(app_factory, tmp_path):
    db = str(tmp_path / "shared.sqlite3")
    first_app = app_factory(ROVER_WEB_DB_PATH=db)
    first = first_app.test_client()
    assert first.post("/api/panels/drone/takeoff", json={"confirmed": True}).status_code == 409
    assert first.post("/api/panels/drone/unlock", json={}).status_code == 200
    assert first.post("/api/panels/drone/takeoff", json={}).status_code == 400
    first_app.extensions["rover_web"].shutdown()  # one server per database: the next one is a restart
    second = app_factory(ROVER_WEB_DB_PATH=db, ROVER_WEB_PANELS_LOG_SHOWN=2).test_client()
    entries = second.get("/api/panels/drone/log").json["entries"]
    assert [(e["control"], e["result"]) for e in entries] == [
        ("takeoff", "invalid"), ("unlock", "unlocked"), ("takeoff", "refused")]
    assert second.get("/api/panels/drone/log?limit=1").json["entries"][0]["result"] == "invalid"
    page = second.get("/panels/drone").get_data(as_text=True)
    rows = re.findall(r'<tr data-id="(\d+)" data-result="(\w+)"', page)
    assert rows == [(str(entries[0]["id"]), "invalid"), (str(entries[1]["id"]), "unlocked")]


def test_the_log_keeps_only_the_newest_entries(app_factory):
    client = app_factory(ROVER_WEB_PANELS_LOG_KEEP=100, ROVER_WEB_PANEL_REFUSALS_PER_MIN=1000).test_client()
    for _ in range(105):
        client.post("/api/panels/drone/stop", json={})
    entries = client.get("/api/panels/drone/log?limit=500").json["entries"]
    assert len(entries) == 100 and entries[0]["id"] == entries[-1]["id"] + 99


def test_pages_render_the_panel_with_its_state(client):
    page = client.get("/panels/drone").get_data(as_text=True)
    assert 'data-panel="drone"' in page and 'data-locked="yes"' in page
    for label in ("Take off", "Return", "Stop", "Start", "Destination (AprilTag id)", "Operator log"):
        assert label in page
    assert re.search(r'data-control="takeoff"[^>]*disabled', page)  # locked, and no status yet
    assert 'data-light="unknown"' in page
    assert 'href="/panels"' in client.get("/").get_data(as_text=True)
    assert client.get("/panels").status_code == 200
    dashboard = client.get("/").get_data(as_text=True)
    assert 'data-panel-summary="drone"' in dashboard and "/static/js/panels/panels." in dashboard
    assert re.search(r'data-channels="[^"]*\bpanel\b', dashboard)


def test_a_malformed_panel_file_fails_at_start_naming_file_panel_and_field(app_factory, server_process, tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text('[panels.drone.controls.takeoff]\nkind = "button"\nlabel = "Take off"\n'
                    'topic = "/control_phase"\ntype = "std_msgs/msg/Int8"\nvalue = 300\n')
    expected = (f"{path}: panel 'drone', control 'takeoff', field 'value': "
                "must be from -128 to 127 for std_msgs/Int8, got 300")
    with pytest.raises(ConfigError) as err:
        app_factory(ROVER_WEB_PANELS_FILE=str(path))
    assert str(err.value) == expected
    server = server_process(env={"ROVER_WEB_PANELS_FILE": str(path)})
    with pytest.raises(RuntimeError, match="server exited with"):
        server.start(timeout=20)
    assert f"rover_web: {expected}" in server.log()
    assert "Traceback" not in server.log()


def test_unlock_attempts_beyond_the_rate_get_429_with_retry_after_and_log_nothing(live_server_factory):
    url = live_server_factory(ROVER_WEB_PANEL_UNLOCKS_PER_MIN=3).url
    for _ in range(3):
        assert post(url, "drone/unlock").status_code == 200
    logged = len(log_entries(url))
    refused = post(url, "drone/unlock")
    assert refused.status_code == 429 and refused.json()["error"] == "rate_limited"
    assert 1 <= int(refused.headers["Retry-After"]) <= 60
    assert "ROVER_WEB_PANEL_UNLOCKS_PER_MIN" in refused.json()["message"]
    assert len(log_entries(url)) == logged


def test_refused_commands_beyond_the_rate_get_429_and_stop_filling_the_operator_log(live_server_factory):
    """Each refusal writes the log every operator reads; one client's loop must not bury it."""
    url = live_server_factory(ROVER_WEB_PANEL_REFUSALS_PER_MIN=4).url
    for _ in range(4):
        assert post(url, "drone/takeoff", {"confirmed": True}).status_code == 409  # locked
    assert len(log_entries(url)) == 4
    for _ in range(5):
        refused = post(url, "drone/takeoff", {"confirmed": True})
        assert refused.status_code == 429 and int(refused.headers["Retry-After"]) >= 1
    assert len(log_entries(url)) == 4
