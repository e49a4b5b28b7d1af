"""The hub over real Zenoh: it hears the robots, marks a killed one lost, stops them all with a
signed command, and the robots refuse a forged or replayed one (tests/integration/hub/conftest.py)."""

from __future__ import annotations

import json
import signal
from pathlib import Path

import pytest
import requests

from rover_web.zenoh_link import signing
from tests.conftest import free_port
from tests.support.waiting import wait_until

from .conftest import FLEET

OTHER_KEY = b"not-the-fleet-key-" * 3


@pytest.fixture
def zenoh_peer(hub_rig):
    """A Zenoh session of the test's own, connected to the hub, as anyone on the Zenoh network."""
    import zenoh

    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps([hub_rig.zenoh_endpoint]))
    config.insert_json5("listen/endpoints", json.dumps([f"tcp/127.0.0.1:{free_port()}"]))
    session = zenoh.open(config)
    # Declarations take a moment to reach a new session: wait until both robots' queryables answer
    # (a malformed command, which each robot refuses without acting on it).
    for robot in ("alpha", "bravo"):
        wait_until(lambda robot=robot: _replies(session, robot, b"{}", 0.5), timeout=10, what=f"{robot}'s queryable")
    yield session
    session.close()


def _replies(session, robot: str, payload: bytes, timeout: float) -> list:
    return [r for r in session.get(f"rover_web/{FLEET}/{robot}/stop", payload=payload, timeout=timeout)
            if r.ok is not None]


def ask(session, robot: str, command: dict) -> dict:
    replies = _replies(session, robot, json.dumps(command).encode(), 3.0)
    assert replies, f"{robot} did not answer"
    return json.loads(replies[0].ok.payload.to_bytes())


def loaded_modules(pid: int) -> str:
    return Path(f"/proc/{pid}/maps").read_text()


def test_the_hub_hears_every_robot_with_its_link(hub_rig):
    heard = wait_until(lambda: (h := hub_rig.heard()) and all(h.get(n, {}).get("heard") == "live"
                                                              for n in ("alpha", "bravo")) and h,
                       timeout=15, what="alpha and bravo heard live")
    for name in ("alpha", "bravo"):
        line = heard[name]
        assert line["url"] == f"{hub_rig.robots[name].url}/robots/{name}/"
        assert (line["namespace"], line["mode"], line["estop"]["engaged"]) == (f"/{name}", "idle", False)
        assert line["summary_age_s"] < 2
    # The robot's own URL, as the hub links it, is that robot's rover_web.
    assert requests.get(heard["alpha"]["url"] + "api/robots", timeout=5).json()["current"] == "alpha"


def test_each_robot_s_position_from_its_simulator_reaches_the_hub(hub_rig):
    # The fix each robot's simulator publishes in its own ROS domain, as the robot itself shows it.
    def positions():
        heard = hub_rig.heard()
        return heard if all(heard.get(n, {}).get("position") for n in ("alpha", "bravo")) else None

    heard = wait_until(positions, timeout=20, what="both robots' positions on the hub")
    for name in ("alpha", "bravo"):
        own = requests.get(hub_rig.robots[name].url + "/api/robots", timeout=5).json()["robots"][0]["position"]
        assert abs(heard[name]["position"]["lat"] - own["lat"]) < 1e-4
        assert abs(heard[name]["position"]["lng"] - own["lng"]) < 1e-4


def test_the_hub_process_has_no_ros(hub_rig):
    # rclpy's extension module is mapped into a process that imported it (the robots' is the control).
    assert "rclpy" not in loaded_modules(hub_rig.hub.proc.pid)
    assert "rclpy" in loaded_modules(hub_rig.robots["alpha"].proc.pid)


def test_a_change_reaches_the_hub_at_once(hub_rig):
    wait_until(lambda: hub_rig.heard().get("alpha", {}).get("heard") == "live", timeout=15, what="alpha live")
    requests.post(hub_rig.robots["alpha"].url + "/api/estop", json={"engaged": True, "by": "local"}, timeout=5)
    try:
        line = wait_until(lambda: (a := hub_rig.heard()["alpha"])["estop"]["engaged"] and a, timeout=1.5,
                          what="alpha's engaged e-stop on the hub")
        assert (line["mode"], line["estop"]["by"]) == ("estop", "local")
    finally:
        hub_rig.release("alpha")
    wait_until(lambda: hub_rig.heard()["alpha"]["estop"]["engaged"] is False, timeout=1.5, what="released on the hub")


def test_stop_all_engages_every_robot_as_the_hub_user(hub_rig):
    wait_until(lambda: all(hub_rig.heard().get(n, {}).get("heard") == "live" for n in ("alpha", "bravo")),
               timeout=15, what="both live")
    assert requests.post(hub_rig.hub.url + "/api/estop/all", json={}, timeout=5).status_code == 401
    try:
        reply = requests.post(hub_rig.hub.url + "/api/estop/all", json={}, headers=hub_rig.headers("viewer"),
                              timeout=10)
        assert reply.status_code == 200, reply.text
        answers = reply.json()
        assert answers["engaged"] is True and answers["by"] == "viewer"
        for name in ("alpha", "bravo"):
            assert answers["robots"][name]["result"] == "engaged"
            state = hub_rig.estop(name)  # each robot's own API
            assert (state["engaged"], state["by"], state["via"]) == (True, "viewer", "hub")
        page = requests.get(hub_rig.hub.url + "/robots", headers=hub_rig.headers(), timeout=5).text
        assert "alpha: engaged" in page and "bravo: engaged" in page
        # Each robot's history on the hub: the stop-all's answer, and the e-stop it saw engaged, by whom.
        def history(name):
            return requests.get(f"{hub_rig.hub.url}/api/robots/{name}/history", headers=hub_rig.headers(),
                                timeout=5).json()["events"]

        for name in ("alpha", "bravo"):
            assert {"by": "viewer", "result": "engaged"} in [e["detail"] for e in history(name)
                                                              if e["event"] == "stop_all"]
            wait_until(lambda name=name: {"by": "viewer"} in [e["detail"] for e in history(name)
                                                               if e["event"] == "estop_engaged"],
                       timeout=3, what=f"{name}'s e-stop in its history")
    finally:
        for name in ("alpha", "bravo"):
            hub_rig.release(name)


def test_a_forged_or_replayed_stop_is_refused(hub_rig, zenoh_peer):
    key = Path(hub_rig.key_file).read_bytes().strip()
    forged = ask(zenoh_peer, "alpha", signing.stop_command(OTHER_KEY, FLEET, "alpha", "mallory"))
    assert (forged["result"], forged["reason"]) == ("refused", "bad_signature")
    assert hub_rig.estop("alpha")["engaged"] is False
    command = signing.stop_command(key, FLEET, "alpha", "tester")
    try:
        first = ask(zenoh_peer, "alpha", command)
        assert first["result"] == "engaged" and signing.answer_checks(key, command, first)
        hub_rig.release("alpha")
        again = ask(zenoh_peer, "alpha", command)
        assert (again["result"], again["reason"]) == ("refused", "replayed")
        assert hub_rig.estop("alpha")["engaged"] is False
    finally:
        hub_rig.release("alpha")


def test_a_forged_summary_is_ignored(hub_rig, zenoh_peer):
    wait_until(lambda: (b := hub_rig.heard().get("bravo", {})).get("heard") == "live" and b["mode"] == "idle",
               timeout=15, what="bravo live and idle")  # an earlier test's release may still be on its way
    status = lambda: requests.get(hub_rig.hub.url + "/api/status", headers=hub_rig.headers(), timeout=5).json()  # noqa: E731
    before = status()["forged_summaries"]
    forged = signing.signed_summary(OTHER_KEY, FLEET, "bravo", 10**6, {"mode": "driving", "title": "bravo"})
    publisher = zenoh_peer.declare_publisher(f"rover_web/{FLEET}/bravo/summary")
    wait_until(lambda: publisher.put(forged) or status()["forged_summaries"] > before, timeout=5,
               what="the forged summary counted", interval=0.2)
    assert hub_rig.heard()["bravo"]["mode"] == "idle"
    publisher.undeclare()


def test_a_killed_robot_is_lost_and_has_no_answer(hub_rig, tmp_path):
    charlie = hub_rig.start_robot("charlie", 52, tmp_path)
    try:
        wait_until(lambda: hub_rig.heard().get("charlie", {}).get("heard") == "live", timeout=15, what="charlie live")
        charlie.stop(signal.SIGKILL)
        wait_until(lambda: hub_rig.heard()["charlie"]["heard"] == "lost", timeout=4, what="charlie lost")
        answers = requests.post(hub_rig.hub.url + "/api/estop/all", json={}, headers=hub_rig.headers(),
                                timeout=10).json()
        assert answers["robots"]["charlie"]["result"] == "no_answer"
        assert answers["robots"]["alpha"]["result"] == answers["robots"]["bravo"]["result"] == "engaged"
        assert answers["engaged"] is False
    finally:
        charlie.stop()
        del hub_rig.robots["charlie"]
        for name in ("alpha", "bravo"):
            hub_rig.release(name)


def test_robots_work_alone_while_the_hub_is_down_and_return_to_it(hub_rig):
    wait_until(lambda: all(hub_rig.heard().get(n, {}).get("heard") == "live" for n in ("alpha", "bravo")),
               timeout=15, what="both live")
    assert hub_rig.hub.stop() == 0
    try:
        # Each robot's own rover_web goes on as if there were no fleet.
        for name in ("alpha", "bravo"):
            url = hub_rig.robots[name].url
            assert requests.post(url + "/api/estop", json={"engaged": True}, timeout=5).json()["engaged"] is True
            hub_rig.release(name)
            assert requests.get(url + "/api/robots", timeout=5).json()["robots"][0]["mode"] == "idle"
    finally:
        hub_rig.hub.start()  # the same Zenoh endpoint and database: the robots' sessions reconnect to it
    wait_until(lambda: all(hub_rig.heard().get(n, {}).get("heard") == "live" for n in ("alpha", "bravo")),
               timeout=15, what="both live again on the restarted hub")
