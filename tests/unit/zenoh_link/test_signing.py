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
    head, _, envelope = payload.rpartition(b".{")
    changed = json.loads(b"{" + envelope)
    changed["summary"] = {"mode": "estop"}
    forged = head + b"." + json.dumps(changed, separators=(",", ":"), sort_keys=True).encode()
    assert signing.open_summary(KEY, "fleet", forged) is None
    assert signing.open_summary(KEY, "fleet", b"not json") is None
    assert signing.open_summary(KEY, "fleet", b"{}") is None


def test_a_summary_s_signature_is_checked_before_its_json_is_parsed(monkeypatch):
    """Issue 40: a forged payload costs one HMAC, never a JSON parse; an oversized one not even that."""
    parsed = []
    real_loads = json.loads
    monkeypatch.setattr(signing.json, "loads", lambda data, *a, **k: parsed.append(len(data)) or real_loads(data))
    forged = signing.signed_summary(OTHER_KEY, "fleet", "alpha", 1, {"mode": "idle", "pad": "x" * 60000}, now=NOW)
    assert signing.open_summary(KEY, "fleet", forged) is None
    assert signing.open_summary(KEY, "fleet", b'{"fleet": "fleet", "summary": "' + b"x" * 50000 + b'"}') is None
    assert parsed == []
    huge = signing.signed_summary(KEY, "fleet", "alpha", 1, {"pad": "x" * signing.SUMMARY_MAX_BYTES}, now=NOW)
    hmacs = []
    monkeypatch.setattr(signing, "_summary_mac", lambda key, env: hmacs.append(1) or b"")
    assert signing.open_summary(KEY, "fleet", huge) is None
    assert (parsed, hmacs) == ([], [])  # refused by its size alone


def test_the_key_file_is_required_and_long_enough(tmp_path):
    with pytest.raises(ConfigError, match="ROVER_WEB_FLEET_KEY_FILE: the Zenoh link needs"):
        signing.load_key(None)
    with pytest.raises(ConfigError, match="cannot read"):
        signing.load_key(str(tmp_path / "missing"))
    short = tmp_path / "short.key"
    short.write_text("abc\n")
    short.chmod(0o600)
    with pytest.raises(ConfigError, match="holds 3 bytes"):
        signing.load_key(str(short))
    good = tmp_path / "fleet.key"
    good.write_text("a" * 64 + "\n")
    good.chmod(0o600)
    assert signing.load_key(str(good)) == b"a" * 64


@pytest.mark.parametrize("mode", [0o644, 0o640, 0o604, 0o620, 0o660])
def test_a_key_file_others_may_read_or_write_is_refused(tmp_path, mode):
    """Issue 40: the database's mode was checked, the fleet key's was not; it is refused (ssh's rule)."""
    key = tmp_path / "fleet.key"
    key.write_text("a" * 64)
    key.chmod(mode)
    with pytest.raises(ConfigError, match=rf"may be read or written by others \(mode {mode:o}\): chmod 600"):
        signing.load_key(str(key))
    key.chmod(0o400)
    assert signing.load_key(str(key)) == b"a" * 64
