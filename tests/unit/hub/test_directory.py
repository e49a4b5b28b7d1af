"""The hub's directory of robots: forged and replayed summaries dropped, lost when silent or gone."""

from __future__ import annotations

from types import SimpleNamespace

from rover_web.hub.directory import Directory
from rover_web.zenoh_link import signing

KEY = b"k" * 32
NOW = 1_800_000_000.0
KEY_EXPR = "rover_web/fleet/alpha/summary"


class Clock:
    t = 100.0

    def __call__(self):
        return self.t


def directory():
    clock = Clock()
    return Directory(KEY, "fleet", lost_after_s=3.0, clock=clock), clock


def alive(d: Directory, name: str, kind: str) -> None:
    d._on_alive(SimpleNamespace(key_expr=f"rover_web/fleet/{name}/alive", kind=f"SampleKind.{kind}"))


def summary(mode: str, sent: float, key: bytes = KEY, robot: str = "alpha") -> bytes:
    return signing.signed_summary(key, "fleet", robot, 1, {"mode": mode, "title": robot}, now=sent)


def test_live_while_its_token_is_there_and_its_summaries_are_fresh():
    d, clock = directory()
    alive(d, "alpha", "PUT")
    assert d.robots()[0]["heard"] == "lost"  # no summary yet
    assert d.summary_arrived(KEY_EXPR, summary("idle", NOW))
    assert [(r["name"], r["heard"], r["mode"]) for r in d.robots()] == [("alpha", "live", "idle")]
    clock.t += 3.5
    assert d.robots()[0]["heard"] == "lost"
    assert d.summary_arrived(KEY_EXPR, summary("idle", NOW + 4))
    assert d.robots()[0]["heard"] == "live"
    alive(d, "alpha", "DELETE")
    assert d.robots()[0]["heard"] == "lost" and d.robots()[0]["alive"] is False


def test_forged_summaries_are_dropped_and_counted():
    d, _ = directory()
    alive(d, "alpha", "PUT")
    assert not d.summary_arrived(KEY_EXPR, summary("idle", NOW, key=b"x" * 32))
    assert not d.summary_arrived(KEY_EXPR, summary("idle", NOW, robot="bravo"))  # bravo's, on alpha's key
    assert not d.summary_arrived(KEY_EXPR, b"garbage")
    assert d.forged == 3
    assert d.robots()[0]["mode"] is None


def test_an_older_summary_played_again_is_ignored():
    d, _ = directory()
    old = summary("idle", NOW)
    assert d.summary_arrived(KEY_EXPR, old)
    assert d.summary_arrived(KEY_EXPR, summary("estop", NOW + 1))
    assert not d.summary_arrived(KEY_EXPR, old)
    assert d.robots()[0]["mode"] == "estop"


def test_only_a_web_address_is_linked():
    d, _ = directory()
    payload = signing.signed_summary(KEY, "fleet", "alpha", 1, {"url": "javascript:alert(1)"}, now=NOW)
    assert d.summary_arrived(KEY_EXPR, payload)
    assert d.robots()[0]["url"] is None
    payload = signing.signed_summary(KEY, "fleet", "alpha", 2, {"url": "https://alpha.example.org/"}, now=NOW + 1)
    assert d.summary_arrived(KEY_EXPR, payload)
    assert d.robots()[0]["url"] == "https://alpha.example.org/"
