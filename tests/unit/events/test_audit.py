"""The audit hub and the features that report to it: who held teleop control, operator-log actions."""

import sqlite3

import pytest

from rover_web.events.audit import AuditHub
from rover_web.panels.oplog import OperatorLog
from rover_web.storage.db import Database
from rover_web.teleop.commands import Limits
from rover_web.teleop.control import TeleopController


class Output:
    def send(self, linear, angular):
        pass

    def zero(self):
        pass


def test_records_are_shaped_like_a_foxglove_event_and_reach_every_listener_until_unsubscribed():
    hub = AuditHub("boat")
    got, other = [], []
    stop = hub.subscribe(got.append)
    hub.subscribe(other.append)
    record = hub.record("estop.engage", by="alice", detail="e-stop engaged by alice", via="api", n=3, ok=True,
                        skipped=None)
    assert set(record) == {"timestamp", "duration", "action", "by", "robot", "detail", "metadata"}
    assert set(record["timestamp"]) == {"sec", "nsec"} and record["duration"] == {"sec": 0, "nsec": 0}
    assert record["robot"] == "boat" and record["metadata"] == {"via": "api", "n": "3", "ok": "true"}
    assert got == [record] == other
    stop()
    hub.record("estop.release", by="bob")
    assert len(got) == 1 and len(other) == 2


def test_a_failing_listener_never_breaks_the_action_nor_the_other_listeners():
    hub = AuditHub()
    got = []
    hub.subscribe(lambda r: 1 / 0)
    hub.subscribe(got.append)
    hub.record("x.y", by="me")
    assert [r["action"] for r in got] == ["x.y"]


def test_teleop_sessions_and_who_held_control_are_recorded():
    ctl = TeleopController(Output(), Limits(5.0, 2.0), rate_hz=40, deadman_s=0.3)
    hub = AuditHub()
    got = []
    hub.subscribe(got.append)
    ctl.audit = hub
    a, b = ctl.connect("alice"), ctl.connect("bob")
    ctl.drive(a, 0.5, 0)
    ctl.takeover(b)
    ctl.release(b)
    ctl.drive(a, 0.1, 0, epoch=a.epoch)
    ctl.disconnect(a)
    ctl.close()
    assert [(r["action"], r["by"]) for r in got] == [
        ("teleop.session_open", "alice"), ("teleop.session_open", "bob"), ("teleop.control_start", "alice"),
        ("teleop.takeover", "bob"), ("teleop.control_end", "bob"), ("teleop.control_start", "alice"),
        ("teleop.control_end", "alice"), ("teleop.session_close", "alice")]
    assert got[3]["metadata"]["previous"] == "alice" and got[6]["metadata"]["reason"] == "disconnected"


@pytest.fixture
def db(tmp_path):
    database = Database(tmp_path / "audit.sqlite3")
    yield database
    database.close()


def test_every_operator_log_entry_is_announced_even_when_the_disk_refuses_it(db):
    # Panels, the geofence and the ROS admin page all write through OperatorLog.
    hub = AuditHub()
    got = []
    hub.subscribe(got.append)
    oplog = OperatorLog(db, keep=10, audit=hub)
    oplog.record("ros", "call_service", "/reset", {"a": 1}, "sent", client="carol")
    assert got[-1]["action"] == "ros.sent" and got[-1]["by"] == "carol"
    assert got[-1]["metadata"] == {"control": "call_service", "value": '{"a": 1}'}
    db.close()
    db.path = "/nonexistent/folder/x.sqlite3"
    with pytest.raises(sqlite3.Error):
        oplog.record("geofence", "replace", "geofence replaced", None, "sent", client="dave")
    assert got[-1]["action"] == "geofence.sent" and got[-1]["by"] == "dave"
