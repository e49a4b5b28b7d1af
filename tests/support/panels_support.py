"""Helpers shared by the control-panel tests: the simulated drone alone, and waiting on the API."""

from __future__ import annotations

import time

import pytest
import requests

from tests.conftest import SimProcess

JSON = {"Content-Type": "application/json"}
STRING = "std_msgs/msg/String"


def drone_process(*args: str) -> SimProcess:
    """`python -m rover_web.sim.drone` (the drone part run alone) in its own process."""
    return SimProcess(list(args), module="rover_web.sim.drone")


@pytest.fixture
def drone_sim():
    """Start the simulated drone with the given arguments; stopped at the end of the test."""
    started = []

    def start(*args: str) -> SimProcess:
        sim = drone_process(*args)
        started.append(sim)
        return sim

    yield start
    for sim in started:
        sim.stop()


def post(base_url: str, path: str, body: dict | None = None) -> requests.Response:
    return requests.post(f"{base_url}/api/panels/{path}", json=body if body is not None else {}, timeout=10)


def display(base_url: str, panel: str, display_id: str) -> dict:
    detail = requests.get(f"{base_url}/api/panels/{panel}", timeout=10).json()
    return next(d for d in detail["displays"] if d["id"] == display_id)


def wait_display(base_url: str, panel: str, display_id: str, value, timeout: float = 15.0) -> dict:
    """Poll the API until a fresh reading of `display_id` equals `value`."""
    deadline = time.monotonic() + timeout
    while True:
        shown = display(base_url, panel, display_id)
        if shown["fresh"] and shown["value"] == value:
            return shown
        if time.monotonic() > deadline:
            raise AssertionError(f"{panel}/{display_id} never showed {value!r}; last {shown}")
        time.sleep(0.05)


def wait_subscribers(base_url: str, panel: str, minimum: dict[str, int], timeout: float = 15.0) -> None:
    """Poll until each control's topic has at least `minimum[control]` matched subscribers."""
    deadline = time.monotonic() + timeout
    while True:
        controls = {c["id"]: c for c in requests.get(f"{base_url}/api/panels/{panel}", timeout=10).json()["controls"]}
        if all(controls[cid]["subscribers"] >= n for cid, n in minimum.items()):
            return
        if time.monotonic() > deadline:
            raise AssertionError(f"subscribers never matched {minimum}: "
                                 f"{ {cid: controls[cid]['subscribers'] for cid in minimum} }")
        time.sleep(0.05)


def feed_status(peer, base_url: str, value: str, panel: str = "drone", timeout: float = 15.0) -> None:
    """Publish /status until the app shows it (discovery matches the two ends a moment apart)."""
    deadline = time.monotonic() + timeout
    while True:
        peer.publish("/status", {"data": value})
        shown = display(base_url, panel, "status")
        if shown["fresh"] and shown["value"] == value:
            return
        assert time.monotonic() < deadline, f"the app never showed status {value!r}: {shown}"
        time.sleep(0.05)


def log_entries(base_url: str, panel: str = "drone", limit: int = 50) -> list[dict]:
    return requests.get(f"{base_url}/api/panels/{panel}/log", params={"limit": limit}, timeout=10).json()["entries"]
