"""A robot's Zenoh link at start: refused without the fleet key, harmless when Zenoh is unreachable."""

from __future__ import annotations

import pytest

from rover_web.config import ConfigError
from rover_web.core.state import rover_of
from rover_web.zenoh_link.robot import RobotLink
from tests.conftest import free_port
from tests.support.waiting import wait_until


def test_zenoh_on_without_a_key_file_refuses_to_start(app_factory):
    with pytest.raises(ConfigError, match=r"^ROVER_WEB_FLEET_KEY_FILE: the Zenoh link needs the fleet's shared key"):
        app_factory(ROVER_WEB_ZENOH_MODE="peer")


def test_a_hub_needs_zenoh(app_factory):
    with pytest.raises(ConfigError, match="^ROVER_WEB_HUB: a hub hears its robots over Zenoh"):
        app_factory(ROVER_WEB_HUB=True)


def test_a_robot_whose_zenoh_is_unreachable_works_alone(app_factory, tmp_path):
    key = tmp_path / "fleet.key"
    key.write_text("k" * 64)
    key.chmod(0o600)
    # A client with nothing to connect to: the session cannot open, and the link keeps retrying.
    app = app_factory(ROVER_WEB_ZENOH_MODE="client", ROVER_WEB_ZENOH_CONNECT=[f"tcp/127.0.0.1:{free_port()}"],
                      ROVER_WEB_FLEET_KEY_FILE=str(key))
    wait_until(lambda: rover_of(app).feature(RobotLink).open_failures >= 1, timeout=5, what="a failed open")
    client = app.test_client()
    assert client.post("/api/estop", json={"engaged": True}).json["engaged"] is True
    assert client.post("/api/estop", json={"engaged": False}).json["engaged"] is False
    assert client.get("/api/robots").json["robots"][0]["mode"] == "idle"
