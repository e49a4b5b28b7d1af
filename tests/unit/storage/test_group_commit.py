"""Group commit: concurrent changes share one transaction, each is answered only after the commit,
and a refused change rolls back alone."""

import sqlite3
import threading
import time

import pytest

from rover_web.storage.db import Database
from rover_web.storage.group_commit import CommitterStopped, GroupCommitter


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "gc.sqlite3")
    database.ensure_schema("CREATE TABLE t (x INTEGER NOT NULL CHECK (x >= 0))")
    yield database
    database.close()


def rows(db):
    conn = sqlite3.connect(db.path)  # another connection: sees only what is committed
    try:
        return sorted(r[0] for r in conn.execute("SELECT x FROM t"))
    finally:
        conn.close()


def test_concurrent_changes_share_commits_and_each_sees_its_own_result(db):
    committer = GroupCommitter(db)
    gate = threading.Event()
    results, committed_when_answered = {}, {}

    def slow(conn):  # holds the committer while the others queue up
        gate.wait(5)
        conn.execute("INSERT INTO t VALUES (0)")
        return "first"

    def writer(i):
        def change(conn):
            conn.execute("INSERT INTO t VALUES (?)", (i,))
            return i * 10
        results[i] = committer.run(change)
        committed_when_answered[i] = i in rows(db)

    first = threading.Thread(target=lambda: results.setdefault(0, committer.run(slow)))
    first.start()
    time.sleep(0.1)
    threads = [threading.Thread(target=writer, args=(i,)) for i in range(1, 21)]
    for t in threads:
        t.start()
    time.sleep(0.2)
    gate.set()
    for t in [first, *threads]:
        t.join(5)
    committer.stop()
    assert results == {0: "first", **{i: i * 10 for i in range(1, 21)}}
    assert all(committed_when_answered.values()) and len(committed_when_answered) == 20
    assert rows(db) == list(range(21))
    assert committer.batches <= 3  # 21 changes, and far fewer fsyncs


def test_a_refused_change_rolls_back_alone(db):
    committer = GroupCommitter(db)
    gate = threading.Event()
    outcome = {}

    def run(name, fn):
        try:
            outcome[name] = committer.run(fn)
        except Exception as exc:  # noqa: BLE001 - the test records what each writer saw
            outcome[name] = exc

    def blocker(conn):
        gate.wait(5)
        conn.execute("INSERT INTO t VALUES (1)")

    def bad(conn):
        conn.execute("INSERT INTO t VALUES (2)")
        conn.execute("INSERT INTO t VALUES (-1)")  # CHECK fails after a first insert

    def refused(conn):
        conn.execute("INSERT INTO t VALUES (3)")
        raise ValueError("no")

    def good(conn):
        return conn.execute("INSERT INTO t VALUES (4)") and 4

    threads = [threading.Thread(target=run, args=("blocker", blocker))]
    threads[0].start()
    time.sleep(0.1)

    for name, fn in [("bad", bad), ("refused", refused), ("good", good)]:
        threads.append(threading.Thread(target=run, args=(name, fn)))
        threads[-1].start()
    time.sleep(0.2)
    gate.set()
    for t in threads:
        t.join(5)
    committer.stop()
    assert isinstance(outcome["bad"], sqlite3.IntegrityError)
    assert isinstance(outcome["refused"], ValueError)
    assert outcome["good"] == 4
    assert rows(db) == [1, 4]  # the bad change's first insert was rolled back with it


def test_after_stop_nothing_is_accepted(db):
    committer = GroupCommitter(db)
    assert committer.run(lambda c: c.execute("INSERT INTO t VALUES (7)").rowcount) == 1
    committer.stop()
    with pytest.raises(CommitterStopped):
        committer.run(lambda c: c.execute("INSERT INTO t VALUES (8)"))
    assert rows(db) == [7]


def test_after_commit_actions_run_once_committed_in_commit_order(db):
    committer = GroupCommitter(db)
    announced, seen_committed = [], []

    def announce(value):
        seen_committed.append(value in rows(db))
        announced.append(value)

    def writer(i):
        committer.run(lambda conn: conn.execute("INSERT INTO t VALUES (?)", (i,)) and i, after_commit=announce)

    threads = [threading.Thread(target=writer, args=(i,)) for i in range(30)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(5)
    conn = sqlite3.connect(db.path)
    try:
        commit_order = [r[0] for r in conn.execute("SELECT x FROM t ORDER BY rowid")]
    finally:
        conn.close()
    assert announced == commit_order and all(seen_committed)

    def broken(_):
        raise RuntimeError("publisher gone")

    with pytest.raises(RuntimeError, match="publisher gone"):
        committer.run(lambda conn: conn.execute("INSERT INTO t VALUES (99)"), after_commit=broken)
    assert 99 in rows(db)  # stored all the same: the writer learns it was not announced
    committer.stop()
