"""The hub's directory of robots: forged, replayed and old summaries dropped; waiting, live, lost
when silent or gone, and forgotten."""

from __future__ import annotations

from types import SimpleNamespace

from rover_web.hub.directory import Directory
from rover_web.zenoh_link import signing

KEY = b"k" * 32
NOW = 1_800_000_000.0
KEY_EXPR = "rover_web/fleet/alpha/summary"


class Clock:
    """The hub's two clocks moved together: monotonic for ages, wall for the summaries' `sent`."""

    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t

    def wall(self):
        return NOW + self.t - 100.0


def directory(forget_after_s: float = 3600.0):
    clock = Clock()
    return Directory(KEY, "fleet", lost_after_s=3.0, window_s=10.0, forget_after_s=forget_after_s, clock=clock,
                     wall=clock.wall), clock


def alive(d: Directory, name: str, kind: str) -> None:
    d._on_alive(SimpleNamespace(key_expr=f"rover_web/fleet/{name}/alive", kind=f"SampleKind.{kind}"))


def summary(mode: str, sent: float, key: bytes = KEY, robot: str = "alpha") -> bytes:
    return signing.signed_summary(key, "fleet", robot, 1, {"mode": mode, "title": robot}, now=sent)


def test_live_while_its_token_is_there_and_its_summaries_are_fresh():
    d, clock = directory()
    alive(d, "alpha", "PUT")
    assert d.robots()[0]["heard"] == "waiting"  # no summary yet
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


def test_heard_but_not_summarised_is_waiting_then_live_or_lost():
    """Issue 42: a robot whose token came and whose first summary has not is `waiting`, not `lost`;
    a token never followed by a summary is lost after lost_after_s (a token proves nothing)."""
    d, clock = directory()
    alive(d, "alpha", "PUT")
    alive(d, "bravo", "PUT")
    assert {r["name"]: (r["heard"], r["summary_age_s"]) for r in d.robots()} == {
        "alpha": ("waiting", None), "bravo": ("waiting", None)}
    clock.t += 1.0
    assert d.summary_arrived(KEY_EXPR, summary("idle", clock.wall()))
    clock.t += 2.5
    assert {r["name"]: r["heard"] for r in d.robots()} == {"alpha": "live", "bravo": "lost"}
    assert d.counts() == {"waiting": 0, "live": 1, "lost": 1}


def test_a_restarted_robot_waits_for_its_new_summary():
    d, clock = directory()
    alive(d, "alpha", "PUT")
    assert d.summary_arrived(KEY_EXPR, summary("idle", clock.wall()))
    alive(d, "alpha", "DELETE")
    clock.t += 10  # its old summary is stale: the new token alone makes it waiting, not lost
    alive(d, "alpha", "PUT")
    assert d.robots()[0]["heard"] == "waiting"
    assert d.summary_arrived(KEY_EXPR, summary("idle", clock.wall()))
    assert d.robots()[0]["heard"] == "live"


def test_a_summary_older_than_the_clock_window_is_refused_after_a_restart_too():
    """Issue 40: a day-old summary, played again to a hub that never saw it, with a token, showed a
    robot long gone as live with its e-stop released."""
    recorded = summary("idle", NOW - 86400)
    d, clock = directory()  # a hub just restarted: it has no newer summary of alpha to compare with
    alive(d, "alpha", "PUT")
    assert not d.summary_arrived(KEY_EXPR, recorded)
    assert not d.summary_arrived(KEY_EXPR, summary("idle", NOW + 11))  # from the future, as far
    assert d.stale == 2 and d.forged == 0
    assert d.robots()[0]["heard"] == "waiting" and d.robots()[0]["mode"] is None
    clock.t += 3.5
    assert d.robots()[0]["heard"] == "lost"  # never live on old news
    assert d.summary_arrived(KEY_EXPR, summary("idle", clock.wall() - 9))  # within the window
    assert d.robots()[0]["heard"] == "live"


def test_an_oversized_summary_is_dropped_unread():
    d, _ = directory()

    class Payload:
        def __len__(self):
            return 50 * 1024 * 1024

        def to_bytes(self):
            raise AssertionError("an oversized payload must not even be copied")

    d._on_summary(SimpleNamespace(key_expr=KEY_EXPR, payload=Payload()))
    assert d.forged == 1 and d.robots() == []


def test_tokens_alone_cannot_grow_the_list_without_bound(monkeypatch):
    from rover_web.hub import directory as module

    monkeypatch.setattr(module, "MAX_ROBOTS", 5)
    d, _ = directory()
    for i in range(20):
        alive(d, f"r{i}", "PUT")
    assert len(d.robots()) == 5
    d, _ = directory()
    alive(d, "x" * 40, "PUT")  # not a robot's name (at most 32 of a-z 0-9 _): nobody
    alive(d, "Évil<b>", "PUT")
    assert d.robots() == []


def test_a_robot_lost_long_enough_is_forgotten_and_the_sweep_tells_the_history():
    d, clock = directory(forget_after_s=60)
    alive(d, "alpha", "PUT")
    assert d.sweep() == [("alpha", "found", {}), ("alpha", "waiting", {})]
    assert d.summary_arrived(KEY_EXPR, summary("idle", clock.wall()))
    assert d.sweep() == [("alpha", "live", {})]
    clock.t += 1
    assert d.summary_arrived(KEY_EXPR, signing.signed_summary(
        KEY, "fleet", "alpha", 2, {"mode": "estop", "estop": {"engaged": True, "by": "ada"}}, now=clock.wall()))
    assert d.sweep() == [("alpha", "estop_engaged", {"by": "ada"})]
    alive(d, "alpha", "DELETE")
    assert d.sweep() == [("alpha", "lost", {})]
    clock.t += 30
    assert d.sweep() == [] and d.robots()[0]["forget_in_s"] == 30
    clock.t += 31
    assert d.sweep() == [("alpha", "forgotten", {"lost_for_s": 61})]
    assert d.robots() == [] and d.forgotten_total == 1
    assert [f["name"] for f in d.recently_forgotten()] == ["alpha"]
    alive(d, "alpha", "PUT")  # it comes back: found again
    assert d.sweep() == [("alpha", "found", {}), ("alpha", "waiting", {})]
