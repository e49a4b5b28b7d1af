"""The hub's history in a real SQLite file: newest first, paged by id, bounded by count and by age."""

from __future__ import annotations

from rover_web.hub.history import History
from rover_web.storage.db import Database


class Clock:
    def __init__(self):
        self.t = 1_800_000_000.0

    def __call__(self):
        return self.t


def history(tmp_path, max_age_s=3600.0, max_rows=10):
    clock = Clock()
    return History(Database(tmp_path / "hub.sqlite3"), max_age_s, max_rows, clock=clock), clock


def test_newest_first_in_pages_that_follow_each_other(tmp_path):
    h, clock = history(tmp_path)
    for i in range(7):
        clock.t += 1
        h.record([("alpha", "live" if i % 2 else "lost", {"i": i}), ("bravo", "found", {})])
    first = h.page("alpha", limit=3)
    assert [e["detail"]["i"] for e in first["events"]] == [6, 5, 4]
    second = h.page("alpha", before=first["next_before"], limit=3)
    third = h.page("alpha", before=second["next_before"], limit=3)
    assert [e["detail"]["i"] for e in second["events"] + third["events"]] == [3, 2, 1, 0]
    assert third["next_before"] is None
    assert h.page("alpha", limit=10_000)["events"][0]["detail"]["i"] == 6  # the limit is capped, not refused here
    assert h.known("bravo") and not h.known("charlie")


def test_at_most_max_rows_per_robot_are_kept(tmp_path):
    h, clock = history(tmp_path, max_rows=10)
    for i in range(25):
        h.record([("alpha", "live", {"i": i})])
    h.record([("bravo", "found", {})])
    kept = h.page("alpha", limit=200)["events"]
    assert [e["detail"]["i"] for e in kept] == list(range(24, 14, -1))
    assert len(h.page("bravo")["events"]) == 1  # another robot's rows are its own


def test_rows_older_than_the_age_bound_are_neither_shown_nor_kept(tmp_path):
    h, clock = history(tmp_path, max_age_s=3600)
    h.record([("alpha", "found", {})])
    clock.t += 1800
    h.record([("alpha", "live", {})])
    clock.t += 2000  # the first is 3800 s old: past the bound
    assert [e["event"] for e in h.page("alpha")["events"]] == ["live"]
    clock.t += 61  # the next write prunes (at most once a minute)
    h.record([("alpha", "lost", {})])
    rows = h.db.connection().execute("SELECT event FROM hub_history ORDER BY id").fetchall()
    assert [r["event"] for r in rows] == ["live", "lost"]


def test_the_table_is_made_once_by_a_numbered_migration(tmp_path):
    h, _ = history(tmp_path)
    h.record([("alpha", "found", {})])
    again = History(h.db, 3600, 10)
    assert again.page("alpha")["events"][0]["event"] == "found"
    version = h.db.connection().execute("SELECT version FROM schema_versions WHERE package = 'hub_history'").fetchone()
    assert version["version"] == 1
