"""Signing and checking the fleet's messages: stop commands, their answers, summaries; the replay guard."""

from __future__ import annotations

import json

import pytest

from rover_web.config import ConfigError
from rover_web.zenoh_link import signing

KEY = b"k" * 32
OTHER_KEY = b"o" * 32
NOW = 1_800_000_000.0


class Clock:
    def __init__(self, t: float = NOW):
        self.t = t

    def __call__(self) -> float:
        return self.t


def guard(window_s: float = 10.0, **kwargs) -> tuple[signing.ReplayGuard, Clock]:
    clock = Clock()
    return signing.ReplayGuard(window_s, clock=clock, **kwargs), clock


def refused(g: signing.ReplayGuard, command, robot: str = "alpha", key: bytes = KEY) -> str:
    with pytest.raises(signing.CommandRefused) as info:
        g.check(key, "fleet", robot, command)
    return info.value.reason


def test_a_signed_command_is_accepted_once():
    g, _ = guard()
    command = signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW)
    assert g.check(KEY, "fleet", "alpha", command)["by"] == "ada"
    assert refused(g, command) == "replayed"


def test_a_command_survives_json_as_sent():
    g, _ = guard()
    command = json.loads(json.dumps(signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW + 0.123456789)))
    g.check(KEY, "fleet", "alpha", command)


@pytest.mark.parametrize("field, value", [("by", "mallory"), ("ts", NOW + 1), ("nonce", "f" * 32)])
def test_any_changed_field_breaks_the_signature(field, value):
    g, _ = guard()
    command = {**signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW), field: value}
    assert refused(g, command) == "bad_signature"


def test_another_key_is_refused():
    g, _ = guard()
    assert refused(g, signing.stop_command(OTHER_KEY, "fleet", "alpha", "ada", now=NOW)) == "bad_signature"


def test_a_command_for_another_robot_or_fleet_is_refused():
    g, _ = guard()
    assert refused(g, signing.stop_command(KEY, "fleet", "bravo", "ada", now=NOW)) == "wrong_robot"
    assert refused(g, signing.stop_command(KEY, "other", "alpha", "ada", now=NOW)) == "wrong_robot"


@pytest.mark.parametrize("offset", [-10.5, 10.5, -3600])
def test_a_timestamp_outside_the_window_is_stale(offset):
    g, _ = guard(10.0)
    assert refused(g, signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW + offset)) == "stale"


@pytest.mark.parametrize("offset", [-9.5, 9.5])
def test_a_timestamp_inside_the_window_is_fresh(offset):
    g, _ = guard(10.0)
    g.check(KEY, "fleet", "alpha", signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW + offset))


@pytest.mark.parametrize("command", [None, [], {}, {"nonce": "short", "ts": NOW, "by": "ada"},
                                     {"nonce": "n" * 32, "ts": True, "by": "ada"},
                                     {"nonce": "n" * 32, "ts": NOW, "by": 3}])
def test_a_malformed_command_is_refused(command):
    g, _ = guard()
    assert refused(g, command) == "malformed"


def test_the_replay_cache_forgets_nonces_once_outside_the_window():
    g, clock = guard(10.0)
    first = signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW)
    g.check(KEY, "fleet", "alpha", first)
    assert len(g) == 1
    clock.t = NOW + 10.5  # the first command is now stale whatever the cache holds
    g.check(KEY, "fleet", "alpha", signing.stop_command(KEY, "fleet", "alpha", "ada", now=clock.t))
    assert len(g) == 1
    assert refused(g, first) == "stale"


def test_the_replay_cache_is_bounded_in_size():
    g, _ = guard(10.0, max_entries=3)
    commands = [signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW) for _ in range(5)]
    for command in commands:
        g.check(KEY, "fleet", "alpha", command)
    assert len(g) == 3
    assert refused(g, commands[-1]) == "replayed"


def test_an_answer_checks_only_for_its_command_and_key():
    command = signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW)
    reply = signing.answer(KEY, "fleet", "alpha", command["nonce"], "engaged")
    assert signing.answer_checks(KEY, command, reply)
    assert not signing.answer_checks(OTHER_KEY, command, reply)
    assert not signing.answer_checks(KEY, command, {**reply, "result": "refused"})
    other = signing.stop_command(KEY, "fleet", "alpha", "ada", now=NOW)
    assert not signing.answer_checks(KEY, other, reply)
    assert not signing.answer_checks(KEY, command, None)


def test_a_summary_opens_only_with_the_key_and_unchanged():
    payload = signing.signed_summary(KEY, "fleet", "alpha", 7, {"mode": "idle"}, now=NOW)
    opened = signing.open_summary(KEY, "fleet", payload)
    assert opened == {"robot": "alpha", "seq": 7, "sent": NOW, "summary": {"mode": "idle"}}
    assert signing.open_summary(OTHER_KEY, "fleet", payload) is None
    assert signing.open_summary(KEY, "other", payload) is None
    envelope = json.loads(payload)
    envelope["summary"] = json.dumps({"mode": "estop"})
    assert signing.open_summary(KEY, "fleet", json.dumps(envelope).encode()) is None
    assert signing.open_summary(KEY, "fleet", b"not json") is None
    assert signing.open_summary(KEY, "fleet", b"{}") is None


def test_the_key_file_is_required_and_long_enough(tmp_path):
    with pytest.raises(ConfigError, match="ROVER_WEB_FLEET_KEY_FILE: the Zenoh link needs"):
        signing.load_key(None)
    with pytest.raises(ConfigError, match="cannot read"):
        signing.load_key(str(tmp_path / "missing"))
    short = tmp_path / "short.key"
    short.write_text("abc\n")
    with pytest.raises(ConfigError, match="holds 3 bytes"):
        signing.load_key(str(short))
    good = tmp_path / "fleet.key"
    good.write_text("a" * 64 + "\n")
    assert signing.load_key(str(good)) == b"a" * 64
