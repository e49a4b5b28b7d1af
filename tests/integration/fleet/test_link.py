"""Issue 20: one robot's silence shows only its link lost. A real ROS peer publishes /boat/odom and
/drone/odom (the link topic /odom, resolved per robot); the drone's falls silent."""

import threading

import pytest

from tests.support.teleop_support import Stick, is_zero, subscribe_cmd_vel, twists, warm_up
from tests.support.waiting import wait_until

from .helpers import CMD_VEL, NAMES, get

pytestmark = pytest.mark.ros

ODOMETRY = "nav_msgs/msg/Odometry"
ODOM = {name: f"/{name}/odom" for name in NAMES}
SPEED = {"boat": 1.25, "drone": 0.75}  # each robot's odometry says a speed of its own
STALE_S = 1.0
SETTINGS = {"ROVER_WEB_STALE_AFTER_S": STALE_S, "ROVER_WEB_STATUS_PERIOD_S": 0.2,
            # Held sticks send a frame every 50 ms; a long deadman keeps it out of what stops them.
            "ROVER_WEB_TELEOP_DEADMAN_S": 5.0}


class Heartbeat:
    """Each robot's odometry every 50 ms from one peer (its only caller); silence(name) stops one."""

    def __init__(self, peer):
        self.peer = peer
        for topic in ODOM.values():
            peer.advertise(topic, ODOMETRY)
        self.live = frozenset(NAMES)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.05):
            for name in sorted(self.live):
                self.peer.publish(ODOM[name], {"header": {"frame_id": "odom"},
                                               "twist": {"twist": {"linear": {"x": SPEED[name]}}}})

    def silence(self, name: str) -> None:
        self.live = self.live - {name}

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)


@pytest.fixture
def heartbeat(ros_peer):
    beats = []

    def make():
        beat = Heartbeat(ros_peer("odom_source"))
        beats.append(beat)
        return beat

    yield make
    for beat in beats:  # before the peer closes under it
        beat.stop()


def link(server, name: str) -> str:
    return get(server.robot[name] + "/api/status")["robot_link"]


def fleet_links(server) -> dict[str, str]:
    return {robot["name"]: robot["link"] for robot in get(server.url + "/api/robots")["robots"]}


def fleet_speeds(server) -> dict[str, float | None]:
    return {r["name"]: r["speed"] and r["speed"]["linear_mps"] for r in get(server.url + "/api/robots")["robots"]}


def test_the_drone_s_silence_loses_only_its_link_and_stops_only_its_drive(fleet_server, ros_peer, heartbeat):
    server = fleet_server(**SETTINGS)
    listener = ros_peer("fleet_listener")
    for name in NAMES:
        subscribe_cmd_vel(listener, topic=CMD_VEL[name])
        warm_up(listener, server.robot[name], topic=CMD_VEL[name])
        assert get(server.robot[name] + "/api/status")["link_topics"] == [ODOM[name]]
    beat = heartbeat()
    wait_until(lambda: link(server, "boat") == link(server, "drone") == "ok", timeout=15, what="both links ok")
    for name in NAMES:  # each robot's status lists its own topics, not the whole fleet's
        listed = [t["topic"] for t in get(server.robot[name] + "/api/status")["topics"]]
        assert ODOM[name] in listed and all(t.startswith(f"/{name}/") for t in listed), listed
    # /api/robots reads the status channel, refreshed every ROVER_WEB_STATUS_PERIOD_S.
    wait_until(lambda: fleet_links(server) == {"boat": "ok", "drone": "ok"}, timeout=2, what="/api/robots: both ok")
    assert wait_until(lambda: fleet_speeds(server) == SPEED, what="each robot's own speed shown")

    sticks = {name: Stick(server.robot[name], name=f"{name}-pilot", value=0.4) for name in NAMES}
    try:
        for name in NAMES:
            listener.wait_for(CMD_VEL[name], lambda m: m["linear"]["x"] == 2.0, timeout=2)

        beat.silence("drone")
        wait_until(lambda: link(server, "drone") == "stale", timeout=STALE_S + 3, what="the drone's link lost")
        assert link(server, "boat") == "ok"
        wait_until(lambda: fleet_links(server) == {"boat": "ok", "drone": "stale"}, timeout=2,
                   what="/api/robots: only the drone's link lost")

        # The link-lost hook stopped the drone's drive; the stick still held there drives nothing
        # until it is let go (re-armed) ...
        stopped = listener.wait_for(CMD_VEL["drone"], is_zero, timeout=2)
        drone_stick = sticks["drone"].client
        drone_stick.wait_for(lambda m: m["type"] == "error" and m["error"] == "rearm_required")
        # ... while the boat's goes on: it moves after the drone stopped, and was never stopped.
        wait_until(lambda: any(t > stopped["t"] and lin == 2.0 for t, lin, _ in twists(listener, CMD_VEL["boat"])),
                   timeout=2, what="the boat still driven after the drone stopped")
        assert all(lin == 2.0 for _, lin, _ in twists(listener, CMD_VEL["boat"]))
        boat_teleop = get(server.robot["boat"] + "/api/teleop")
        assert boat_teleop["holder"]["name"] == "boat-pilot" and boat_teleop["moving"] is True
        assert get(server.robot["drone"] + "/api/teleop")["last_stop"]["reason"] == "link_lost"
        after = [lin for t, lin, _ in twists(listener, CMD_VEL["drone"]) if t >= stopped["t"]]
        assert after and set(after) == {0.0}
    finally:
        for stick in sticks.values():
            stick.close()
