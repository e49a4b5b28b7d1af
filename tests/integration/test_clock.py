"""Deadman and stale times use a monotonic clock: a wall-clock jump of an hour changes nothing (issue 21).

The server runs under libfaketime (Debian's `faketime`, installed by scripts/bootstrap.sh) with
its monotonic clock left alone: the offset file moves the server's wall clock an hour forward and
back while a joystick drives and the simulator's /odom keeps the link fresh.
"""

import ast
import email.utils
import time
from pathlib import Path

import pytest
import requests

import rover_web
from tests.support.teleop_support import TeleopClient, drive_at, is_zero, subscribe_cmd_vel, twists, warm_up
from tests.support.waiting import wait_until

FAKETIME = Path("/usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1")


def server_wall_clock(url: str) -> float:
    """The server's idea of the wall clock: its HTTP Date header."""
    return email.utils.parsedate_to_datetime(requests.get(url + "/api/status", timeout=5).headers["Date"]).timestamp()


def link(url: str) -> str:
    return requests.get(url + "/api/status", timeout=5).json()["robot_link"]


@pytest.mark.ros
def test_a_wall_clock_jump_of_an_hour_changes_neither_the_deadman_nor_the_link(
        server_process, sim_process, ros_peer, tmp_path):
    if not FAKETIME.exists():
        pytest.fail(f"{FAKETIME} is missing: scripts/bootstrap.sh installs Debian's faketime")
    offset = tmp_path / "faketime"
    offset.write_text("+0\n")
    # The offset file is re-read at most once a second (FAKETIME_NO_CACHE re-read it on every
    # clock call, and the server spent its time reading a file: frames were held up for the
    # deadman to find, a stop that was libfaketime's, not the wall clock's).
    server = server_process(env={"LD_PRELOAD": str(FAKETIME), "FAKETIME_TIMESTAMP_FILE": str(offset),
                                 "FAKETIME_CACHE_DURATION": "1", "FAKETIME_DONT_FAKE_MONOTONIC": "1"}).start()
    sim_process("--only", "rover")
    peer = ros_peer("clock_listener")
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    wait_until(lambda: link(server.url) == "ok", 20, "the simulator's /odom makes the link ok")
    peer.clear("/cmd_vel")  # a warm-up stop still on its way must not count as a stop mid-drive

    client = TeleopClient(server.url)
    deadman_s = client.hello["deadman_max_s"]  # the hard bound: zero whatever the ramp does
    before = server_wall_clock(server.url)
    drive_at(client, [(0.4, 0.0)] * 8)
    offset.write_text("+3600\n")  # an hour forward, mid-drive
    deadline = time.monotonic() + 5
    while server_wall_clock(server.url) - before < 3500:  # fresh input until the server has seen the jump
        assert time.monotonic() < deadline, "libfaketime did not move the server's wall clock"
        drive_at(client, [(0.4, 0.0)] * 4)
    drive_at(client, [(0.4, 0.0)] * 40)  # 1 s more of fresh input, an hour later
    # A wall-clock deadman would have found the last input an hour old and stopped the robot.
    # The one other stop that may come mid-drive is the robot's own link going quiet (the
    # simulator's /odom held up on a loaded machine): that is not the deadman, and it says so.
    last_stop = requests.get(server.url + "/api/teleop", timeout=5).json()["last_stop"]
    if any(lin == 0.0 for _, lin, _ in twists(peer)):
        assert last_stop and last_stop["reason"] == "link_lost", f"stopped while input was fresh: {last_stop}"
        wait_until(lambda: link(server.url) == "ok", 10, "the link is ok again")
        client.drive(0.0, 0.0)  # back to neutral: re-armed, as after any stop the operator did not ask for
    assert link(server.url) == "ok"

    peer.clear("/cmd_vel")
    times = drive_at(client, [(0.5, 0.0)] * 8)
    offset.write_text("-3600\n")  # and back, past where it started: the last input now looks an hour ahead
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=3.0)
    assert zero["t"] - times[-1] <= deadman_s + 0.5, zero["t"] - times[-1]  # stopped by the deadman, not never
    for _ in range(4):
        assert link(server.url) == "ok"  # stale times are monotonic too
        time.sleep(0.25)
    client.close()


# What measures an age or a deadline must not read the wall clock; records may (their timestamps).
WALL_CLOCK_ALLOWED = {
    "auth/accounts.py": "created_at and revoked_at of users and tokens",
    "auth/tls.py": "certificate validity dates",
    "auth/sessions.py": "a session's expiry, kept on disk across restarts as a cookie's expiry is",
    "estop/service.py": "`since` of the latch, shown to people and kept on disk",
    "teleop/control.py": "times in the teleop state shown to people (deadman and rate use the monotonic clock)",
    "scan_the_code/service.py": "when a code was seen, shown to people (cycles use the monotonic clock)",
    "geofence/service.py": "`since` shown to people",
    "geofence/store.py": "when the fence was saved",
    "layouts/store.py": "when a layout was last changed, shown to people (updated_at)",
    "prefs/store.py": "when a user's choices last changed (updated_at)",
    "panels/oplog.py": "when a log line was written",
    "plot/routes.py": "the plot's time axis is wall time, as its CSV export shows it",
    "plot/service.py": "when a sample arrived, for the plot's time axis",
    "ros_admin/goals.py": "when a goal was sent, shown to people",
    "web/status.py": "/api/ping's answer: the server's clock, shown beside the round trip",
    "waypoints/store.py": "created_at of a waypoint",
    "sim/timecode.py": "the time code is the camera's wall clock, read against the viewer's: glass to glass",
    "hub/stop_all.py": "when a stop-all was sent, shown to people",
    "recording/service.py": "a running recording's duration, from its start kept on disk across restarts",
    "recording/upload.py": "an upload's id and when it was uploaded, shown to people",
    "hub/directory.py": "a summary's signed send time against the hub's clock (its clock window, issue 40), and "
                        "when a state changed, shown to people; lost and forgotten use the monotonic clock",
    "hub/history.py": "when each state change happened, kept on disk and shown to people",
    "nav2/service.py": "when a goal was sent, ended or canceled and when a server's state was read, shown to people",
    "view3d/service.py": "a poses frame's send time, read by a viewer in another process (its frame age)",
    "zenoh_link/signing.py": "a signed stop's and summary's time, checked on another machine (monotonic clocks are "
                             "each machine's own); lost and stale on the hub use the monotonic clock",
}


def test_only_records_read_the_wall_clock():
    root = Path(rover_web.__file__).parent
    readers = set()
    for path in root.rglob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Attribute) and node.attr in ("time", "now", "utcnow", "today") and \
                    isinstance(node.value, (ast.Name, ast.Attribute)) and \
                    getattr(node.value, "id", getattr(node.value, "attr", "")) in ("time", "datetime", "date"):
                readers.add(str(path.relative_to(root)))
    assert readers <= set(WALL_CLOCK_ALLOWED), sorted(readers - set(WALL_CLOCK_ALLOWED))
