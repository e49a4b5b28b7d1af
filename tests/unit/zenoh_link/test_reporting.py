"""When a robot's summary goes out: once a second, and at once when what an operator must see changes."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from rover_web.zenoh_link import robot as robot_module
from rover_web.zenoh_link import signing
from rover_web.zenoh_link.robot import PERIOD_S, RobotLink
from rover_web.zenoh_link.session import LinkSettings

KEY = b"k" * 32


class Publisher:
    def __init__(self):
        self.sent: list[dict] = []

    def put(self, payload: bytes) -> None:
        self.sent.append(signing.open_summary(KEY, "fleet", payload)["summary"])


@pytest.fixture
def rig(monkeypatch):
    line = {"link": "ok", "mode": "idle", "operator": None, "estop": {"engaged": False}, "alerts": [],
            "speed": {"linear_mps": 0.0}}
    monkeypatch.setattr(robot_module, "robot_summary", lambda rover, url: dict(line))
    rover = SimpleNamespace(robot=SimpleNamespace(name="alpha"))
    link = RobotLink([rover], LinkSettings("peer", [], [], None, False, "fleet", KEY), None, 10.0)
    robot = link._robots[0]
    robot.publisher = Publisher()
    return link, robot, line


def test_a_summary_once_a_second_when_nothing_changes(rig):
    link, robot, line = rig
    link._report(robot, 100.0)
    line["speed"] = {"linear_mps": 0.5}  # a speed alone waits for the next second
    link._report(robot, 100.0 + PERIOD_S / 2)
    assert len(robot.publisher.sent) == 1
    link._report(robot, 100.0 + PERIOD_S)
    assert [s["speed"]["linear_mps"] for s in robot.publisher.sent] == [0.0, 0.5]


@pytest.mark.parametrize("field, value", [("mode", "estop"), ("estop", {"engaged": True}), ("link", "stale"),
                                          ("operator", "ada"), ("alerts", ["outside the geofence"])])
def test_a_change_an_operator_must_see_goes_out_at_once(rig, field, value):
    link, robot, line = rig
    link._report(robot, 100.0)
    line[field] = value
    link._report(robot, 100.1)
    assert [s[field] for s in robot.publisher.sent][-1] == value and len(robot.publisher.sent) == 2
