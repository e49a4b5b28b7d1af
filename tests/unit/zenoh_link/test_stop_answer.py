"""A robot's answer to the hub's stop: the e-stop engaged through its service for a good command
only, as by the hub's user via "hub", and a signed answer either way."""

from __future__ import annotations

import json
from types import SimpleNamespace

from rover_web.estop import EStopService
from rover_web.zenoh_link import signing
from rover_web.zenoh_link.robot import RobotLink
from rover_web.zenoh_link.session import LinkSettings

KEY = b"k" * 32


class EStop:
    def __init__(self):
        self.engages: list[tuple[str, str]] = []

    def engage(self, by: str, via: str = "api") -> dict:
        self.engages.append((by, via))
        return {"engaged": True, "since": 1.0, "by": by, "via": via}


def robot():
    estop = EStop()
    rover = SimpleNamespace(robot=SimpleNamespace(name="alpha"),
                            feature=lambda cls: estop if cls is EStopService else None)
    link = RobotLink([rover], LinkSettings("peer", [], [], None, False, "fleet", KEY), None, 10.0)
    return link, rover, estop


def test_a_good_command_engages_as_the_hub_user():
    link, rover, estop = robot()
    command = signing.stop_command(KEY, "fleet", "alpha", "ada")
    answer = link.stop_answer(rover, "alpha", json.dumps(command).encode())
    assert estop.engages == [("ada", "hub")]
    assert answer["result"] == "engaged" and signing.answer_checks(KEY, command, answer)


def test_a_bad_command_engages_nothing_and_says_why():
    link, rover, estop = robot()
    forged = signing.stop_command(b"x" * 32, "fleet", "alpha", "mallory")
    answer = link.stop_answer(rover, "alpha", json.dumps(forged).encode())
    assert (answer["result"], answer["reason"]) == ("refused", "bad_signature")
    assert signing.answer_checks(KEY, forged, answer)  # the refusal is the robot's own, signed
    for payload in (b"", b"not json", b"[]"):
        assert link.stop_answer(rover, "alpha", payload)["reason"] == "malformed"
    assert estop.engages == []
