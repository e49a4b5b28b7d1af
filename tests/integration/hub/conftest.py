"""A fleet hub and two robots, each a real process on 127.0.0.1, joined by real Zenoh sessions.

The hub (`ROVER_WEB_HUB=true flask run`) listens for Zenoh on a free loopback port, with sign-in
required (one user per role); robots alpha and bravo are whole rover_webs, each in its own ROS
domain with its own simulated rover (`python -m rover_web.sim`: the GPS fix its summary's
position comes from), connecting to the hub and listening on a
loopback port of their own (peers find each other through the hub: gossip; multicast scouting is
off, so nothing leaves loopback). The processes are module-scoped: starting a rover_web costs
seconds, and the tests release what they engage.
"""

from __future__ import annotations

import os
import secrets
from dataclasses import dataclass, field

import pytest
import requests

from tests.conftest import ServerProcess, SimProcess, free_port
from tests.support.auth import add_users

FLEET = "testfleet"


def _domain(offset: int) -> str:
    """A ROS domain of the robot's own, apart from the session's (tests/conftest.py)."""
    return str((int(os.environ["ROS_DOMAIN_ID"]) + offset) % 200 + 1)


@dataclass
class HubRig:
    hub: ServerProcess
    zenoh_endpoint: str
    key_file: str
    tokens: dict
    robots: dict[str, ServerProcess] = field(default_factory=dict)
    sims: list[SimProcess] = field(default_factory=list)

    def headers(self, role: str = "viewer") -> dict:
        return {"Authorization": f"Bearer {self.tokens[role]}"}

    def heard(self) -> dict[str, dict]:
        reply = requests.get(self.hub.url + "/api/robots", headers=self.headers(), timeout=5)
        reply.raise_for_status()
        return {r["name"]: r for r in reply.json()["robots"]}

    def robot_env(self, name: str, offset: int, url: str) -> dict:
        return {"ROVER_WEB_ROBOTS": name, "ROS_DOMAIN_ID": _domain(offset), "ROVER_WEB_ZENOH_MODE": "peer",
                "ROVER_WEB_ZENOH_CONNECT": self.zenoh_endpoint,
                "ROVER_WEB_ZENOH_LISTEN": f"tcp/127.0.0.1:{free_port()}",
                "ROVER_WEB_FLEET_NAME": FLEET, "ROVER_WEB_FLEET_KEY_FILE": self.key_file,
                "ROVER_WEB_PUBLIC_URL": url}

    def start_robot(self, name: str, offset: int, db_dir) -> ServerProcess:
        port = free_port()
        env = self.robot_env(name, offset, f"http://127.0.0.1:{port}")
        env["ROVER_WEB_DB_PATH"] = str(db_dir / f"{name}.sqlite3")
        if not any(s.proc.args[-1] == name for s in self.sims):  # a restarted robot keeps its simulator
            self.sims.append(SimProcess(["--only", "rover", "--robots", name], ROS_DOMAIN_ID=env["ROS_DOMAIN_ID"]))
        robot = ServerProcess(port, env)
        self.robots[name] = robot
        return robot.start()

    def estop(self, name: str) -> dict:
        return requests.get(self.robots[name].url + "/api/estop", timeout=5).json()

    def release(self, name: str) -> None:
        reply = requests.post(self.robots[name].url + "/api/estop", json={"engaged": False}, timeout=5)
        assert reply.status_code == 200 and reply.json()["engaged"] is False, reply.text


@pytest.fixture(scope="module")
def hub_rig(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("hub")
    key_file = tmp / "fleet.key"
    key_file.write_text(secrets.token_hex(32) + "\n")
    key_file.chmod(0o600)
    hub_db = tmp / "hub.sqlite3"
    tokens = add_users(hub_db)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    hub = ServerProcess(env={"ROVER_WEB_HUB": "true", "ROVER_WEB_ZENOH_MODE": "peer",
                             "ROVER_WEB_ZENOH_LISTEN": endpoint, "ROVER_WEB_FLEET_NAME": FLEET,
                             "ROVER_WEB_FLEET_KEY_FILE": str(key_file),
                             "ROVER_WEB_FLEET_LOST_AFTER_S": "2", "ROVER_WEB_FLEET_STOP_TIMEOUT_S": "1.5",
                             "ROVER_WEB_AUTH": "required", "ROVER_WEB_DB_PATH": str(hub_db)})
    rig = HubRig(hub, endpoint, str(key_file), tokens)
    try:
        hub.start()
        for offset, name in enumerate(("alpha", "bravo"), start=50):
            rig.start_robot(name, offset, tmp)
        yield rig
    finally:
        for robot in rig.robots.values():
            robot.stop()
        for sim in rig.sims:
            sim.stop()
        assert hub.stop() == 0, "the hub did not end on SIGTERM"  # Zenoh's threads must not hold it
