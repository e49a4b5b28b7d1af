"""The Zenoh settings: off by default, and refused with one sentence when on without the fleet key."""

from __future__ import annotations

import pytest

from rover_web import config
from rover_web.config import ConfigError
from rover_web.zenoh_link.session import link_settings, robot_of


def settings(**extra):
    return config.load({f"ROVER_WEB_{k}": v for k, v in extra.items()}, environ={})


def test_off_by_default():
    assert link_settings(settings()) is None


def test_on_without_a_key_file_is_refused():
    with pytest.raises(ConfigError, match=r"^ROVER_WEB_FLEET_KEY_FILE: the Zenoh link needs the fleet's shared key"):
        link_settings(settings(ZENOH_MODE="peer"))


def test_bad_values_are_named(tmp_path):
    key = tmp_path / "fleet.key"
    key.write_text("k" * 32)
    key.chmod(0o600)
    with pytest.raises(ConfigError, match="ROVER_WEB_FLEET_NAME"):
        link_settings(settings(ZENOH_MODE="peer", FLEET_KEY_FILE=str(key), FLEET_NAME="Bad/Name"))
    with pytest.raises(ConfigError, match="ROVER_WEB_ZENOH_CONNECT"):
        link_settings(settings(ZENOH_MODE="peer", FLEET_KEY_FILE=str(key), ZENOH_CONNECT=["127.0.0.1:7447"]))
    with pytest.raises(ConfigError, match="ROVER_WEB_PUBLIC_URL"):
        link_settings(settings(ZENOH_MODE="peer", FLEET_KEY_FILE=str(key), PUBLIC_URL="javascript:alert(1)"))
    with pytest.raises(ConfigError, match="client mode needs"):
        link_settings(settings(ZENOH_MODE="client", FLEET_KEY_FILE=str(key)))
    with pytest.raises(ConfigError, match="ROVER_WEB_ZENOH_MODE"):
        settings(ZENOH_MODE="router")


def test_on_with_a_key(tmp_path):
    key = tmp_path / "fleet.key"
    key.write_text("k" * 40)
    key.chmod(0o600)
    link = link_settings(settings(ZENOH_MODE="client", FLEET_KEY_FILE=str(key), ZENOH_CONNECT=["tcp/127.0.0.1:7447"]))
    assert (link.mode, link.connect, link.fleet, link.key, link.multicast_scouting) == (
        "client", ["tcp/127.0.0.1:7447"], "fleet", b"k" * 40, False)


def test_robot_of_a_key_expression():
    assert robot_of("rover_web/fleet/alpha/summary") == "alpha"
    assert robot_of("rover_web/fleet/summary") == ""
