"""The hub's view of a robot over real Zenoh sessions: waiting, live, lost, forgotten (issue 42),
old and oversized summaries refused (issue 40), the derived link, and the history API's pages.

The hub is a real process (`ROVER_WEB_HUB=true flask run`); "charlie" and "delta" are Zenoh
sessions of the test's own that do what a robot's link does (a liveliness token, signed
summaries), so each step happens when the test says; "echo" is a whole rover_web started with
ROVER_WEB_HOST/_PORT and no ROVER_WEB_PUBLIC_URL, for the link derived from its address.
"""

from __future__ import annotations

import json
import os
import secrets
import time

import pytest
import requests
from prometheus_client.parser import text_string_to_metric_families

from rover_web.zenoh_link import signing
from tests.conftest import ServerProcess, SimProcess, free_port
from tests.support.auth import add_users
from tests.support.waiting import wait_until

FLEET = "statesfleet"
FORGET_AFTER_S = 10  # the setting's least


class Rig:
    def __init__(self, hub: ServerProcess, endpoint: str, key: bytes, key_file: str, tokens: dict):
        self.hub, self.endpoint, self.key, self.key_file, self.tokens = hub, endpoint, key, key_file, tokens

    def get(self, path: str, **params):
        return requests.get(self.hub.url + path, params=params, timeout=5,
                            headers={"Authorization": f"Bearer {self.tokens['viewer']}"})

    def heard(self) -> dict[str, dict]:
        return {r["name"]: r for r in self.get("/api/robots").json()["robots"]}

    def state(self, name: str) -> str | None:
        return self.heard().get(name, {}).get("heard")


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hubstates")
    key = secrets.token_hex(32).encode()
    key_file = tmp / "fleet.key"
    key_file.write_bytes(key)
    key_file.chmod(0o600)
    db = tmp / "hub.sqlite3"
    tokens = add_users(db)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    hub = ServerProcess(env={"ROVER_WEB_HUB": "true", "ROVER_WEB_ZENOH_MODE": "peer",
                             "ROVER_WEB_ZENOH_LISTEN": endpoint, "ROVER_WEB_FLEET_NAME": FLEET,
                             "ROVER_WEB_FLEET_KEY_FILE": str(key_file), "ROVER_WEB_FLEET_LOST_AFTER_S": "2",
                             "ROVER_WEB_FLEET_FORGET_AFTER_S": str(FORGET_AFTER_S),
                             "ROVER_WEB_AUTH": "required", "ROVER_WEB_DB_PATH": str(db)})
    hub.start()
    try:
        yield Rig(hub, endpoint, key, str(key_file), tokens)
    finally:
        assert hub.stop() == 0


@pytest.fixture
def session(rig):
    import zenoh

    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps([rig.endpoint]))
    config.insert_json5("listen/endpoints", json.dumps([f"tcp/127.0.0.1:{free_port()}"]))
    s = zenoh.open(config)
    yield s
    s.close()


def _summary(rig: Rig, name: str, seq: int, sent: float | None = None, **fields) -> bytes:
    line = {"title": name, "mode": "idle", "link": "ok", "estop": {"engaged": False, "since": None, "by": None},
            **fields}
    return signing.signed_summary(rig.key, FLEET, name, seq, line, now=sent)


def test_waiting_then_live_then_lost_then_forgotten_with_the_history_and_metrics(rig, session):
    token = session.liveliness().declare_token(f"rover_web/{FLEET}/charlie/alive")
    line = wait_until(lambda: rig.heard().get("charlie"), timeout=5, what="charlie heard")
    assert (line["heard"], line["summary_age_s"]) == ("waiting", None)  # not `lost` while its first summary comes
    publisher = session.declare_publisher(f"rover_web/{FLEET}/charlie/summary")
    seq = iter(range(1, 1000))
    wait_until(lambda: publisher.put(_summary(rig, "charlie", next(seq))) or rig.state("charlie") == "live",
               timeout=5, interval=0.2, what="charlie live")
    publisher.put(_summary(rig, "charlie", next(seq), estop={"engaged": True, "since": time.time(), "by": "ada"},
                           mode="estop"))
    wait_until(lambda: rig.heard()["charlie"]["estop"]["engaged"], timeout=3, what="charlie's e-stop on the hub")
    token.undeclare()
    line = wait_until(lambda: (c := rig.heard()["charlie"])["heard"] == "lost" and c, timeout=4, what="charlie lost")
    lost_at = time.monotonic()
    assert 0 < line["forget_in_s"] <= FORGET_AFTER_S
    metrics = {f.name: f for f in text_string_to_metric_families(rig.get("/metrics").text)}
    assert [s.value for s in metrics["rover_web_hub_robot_state"].samples
            if s.labels == {"robot": "charlie", "state": "lost"}] == [1.0]
    wait_until(lambda: "charlie" not in rig.heard(), timeout=FORGET_AFTER_S + 3, what="charlie forgotten")
    assert time.monotonic() - lost_at >= FORGET_AFTER_S - 1
    state = rig.get("/api/robots").json()
    assert "charlie" in [f["name"] for f in state["forgotten"]] and state["forget_after_s"] == FORGET_AFTER_S
    assert "charlie" in rig.get("/robots").text  # the page says who was forgotten
    metrics = {f.name: f for f in text_string_to_metric_families(rig.get("/metrics").text)}
    assert metrics["rover_web_hub_robots_forgotten"].samples[0].value >= 1
    assert not [s for s in metrics["rover_web_hub_robot_alive"].samples if s.labels["robot"] == "charlie"]
    history = rig.get("/api/robots/charlie/history").json()
    events = [e["event"] for e in history["events"]]
    assert events == ["forgotten", "lost", "estop_engaged", "live", "waiting", "found"], events
    assert history["events"][2]["detail"] == {"by": "ada"}
    assert [e["id"] for e in history["events"]] == sorted((e["id"] for e in history["events"]), reverse=True)
    # Paged: two at a time, newest first, every row once.
    pages, before = [], None
    while True:
        page = rig.get("/api/robots/charlie/history", limit=2, **({"before": before} if before else {})).json()
        pages.append([e["event"] for e in page["events"]])
        before = page["next_before"]
        if before is None:
            break
    assert pages == [["forgotten", "lost"], ["estop_engaged", "live"], ["waiting", "found"]]
    publisher.undeclare()


def test_the_history_api_refuses_what_it_cannot_answer(rig):
    for params in ({"limit": 0}, {"limit": 201}, {"limit": "ten"}, {"before": -1}, {"before": "1e3"},
                   {"before": "9" * 30}):
        reply = rig.get("/api/robots/charlie/history", **params)
        assert (reply.status_code, reply.json()["error"]) == (400, "bad_value"), params
    assert rig.get("/api/robots/nobody/history").json()["error"] == "unknown_robot"
    assert rig.get("/api/robots/Bad..Name/history").status_code == 404
    assert requests.get(rig.hub.url + "/api/robots/charlie/history", timeout=5).status_code == 401


def test_old_news_and_oversized_summaries_are_refused(rig, session):
    """Issue 40: after a restart the hub has nothing to compare with; a day-old summary played again
    with a token must not show the robot live, its e-stop released; a 1 MB one is dropped unread."""
    token = session.liveliness().declare_token(f"rover_web/{FLEET}/delta/alive")
    publisher = session.declare_publisher(f"rover_web/{FLEET}/delta/summary")
    before = rig.get("/api/status").json()
    recorded = _summary(rig, "delta", 5, sent=time.time() - 86400)
    wait_until(lambda: publisher.put(recorded) or rig.get("/api/status").json()["stale_summaries"]
               > before["stale_summaries"], timeout=5, interval=0.2, what="the old summary refused")
    huge = b"rws1." + b"0" * 64 + b"." + b"x" * (1024 * 1024)
    wait_until(lambda: publisher.put(huge) or rig.get("/api/status").json()["forged_summaries"]
               > before["forged_summaries"], timeout=5, interval=0.2, what="the oversized summary dropped")
    line = rig.heard()["delta"]
    assert line["heard"] in ("waiting", "lost") and line["mode"] is None and line["estop"]["engaged"] is None
    wait_until(lambda: rig.state("delta") == "lost", timeout=4, what="delta lost: a token alone is not a robot")
    publisher.put(_summary(rig, "delta", 6))  # a fresh one, and it is live
    wait_until(lambda: rig.state("delta") == "live", timeout=3, what="delta live on fresh news")
    token.undeclare()
    publisher.undeclare()


def test_a_robot_with_no_public_url_links_to_its_own_address(rig, tmp_path):
    port = free_port()
    domain = str((int(os.environ["ROS_DOMAIN_ID"]) + 60) % 200 + 1)
    sim = SimProcess(["--only", "rover", "--robots", "echo"], ROS_DOMAIN_ID=domain)
    robot = ServerProcess(port, {"ROVER_WEB_ROBOTS": "echo", "ROS_DOMAIN_ID": domain, "ROVER_WEB_ZENOH_MODE": "peer",
                                 "ROVER_WEB_ZENOH_CONNECT": rig.endpoint,
                                 "ROVER_WEB_ZENOH_LISTEN": f"tcp/127.0.0.1:{free_port()}",
                                 "ROVER_WEB_FLEET_NAME": FLEET, "ROVER_WEB_FLEET_KEY_FILE": rig.key_file,
                                 "ROVER_WEB_HOST": "127.0.0.1", "ROVER_WEB_PORT": str(port),
                                 "ROVER_WEB_DB_PATH": str(tmp_path / "echo.sqlite3")})
    try:
        robot.start()
        line = wait_until(lambda: (e := rig.heard().get("echo")) and e["heard"] == "live" and e, timeout=15,
                          what="echo live")
        assert line["url"] == f"http://127.0.0.1:{port}/robots/echo/"
        assert requests.get(line["url"] + "api/robots", timeout=5).json()["current"] == "echo"
        # The history is written by the database's committer thread: read it once it has landed.
        events = wait_until(lambda: (ev := [e["event"] for e in rig.get("/api/robots/echo/history").json()["events"]])
                            and "live" in ev and ev, timeout=10, what="echo's history")
        assert events[-1] == "found" and "live" in events
    finally:
        robot.stop()
        sim.stop()
