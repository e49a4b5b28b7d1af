"""Stall-then-burst: frames queued while the link or the server was stalled never move the robot.

Two real stalls. (1) The network: the client talks through a TCP proxy that stops forwarding in
both directions, as a Wi-Fi dropout does; the client keeps writing, the server hears nothing and
stops the robot by its deadman's hard bound, then the proxy delivers everything in one burst. (2) The server
itself: the app runs in its own process, which is frozen with SIGSTOP while the client keeps
writing into its socket; on SIGCONT the app finds a pile of frames and an expired deadman.

In both, the burst really reaches the server (it answers every queued frame with `stale_epoch`),
nothing the burst asked for is ever published, and a frame sent after the client heard the new
epoch drives again, so the checks are not vacuous.
"""

import os
import signal
import time

import pytest

from tests.support.teleop_support import (
    StallingProxy,
    TeleopClient,
    drive_at,
    is_zero,
    subscribe_cmd_vel,
    twists,
    warm_up,
)
from tests.support.waiting import wait_until

BURST_VALUE = 0.8   # what the operator "held" during the stall: 4.0 m/s must never appear
# 1.4 s at 40 Hz: longer than ROVER_WEB_TELEOP_DEADMAN_MAX_S (1 s), past which the server stops
# whatever happens (a shorter stall ends in a resumed drive: test_jittery_link.py), and few enough
# that every reply fits the socket's outbox (64 messages) when the whole burst is read at once.
BURST_FRAMES = 56


def drive_then_check_burst_was_refused(client, peer, stall, unstall):
    drive_at(client, [(0.5, 0.0)] * 12)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.5, timeout=2.0)

    stall()
    t_stall = time.monotonic()
    drive_at(client, [(BURST_VALUE, 0.0)] * BURST_FRAMES, epoch=0)  # what a client sends while it knows no better
    t_unstall = time.monotonic()
    unstall()

    time.sleep(0.6)  # far longer than the burst takes to be read
    received = twists(peer)
    assert all(lin != BURST_VALUE * 5 for _, lin, _ in received), "a queued frame moved the robot"
    zero_t = next(t for t, lin, ang in received if t > t_stall and lin == 0.0 and ang == 0.0)
    assert all(lin == 0.0 for t, lin, _ in received if t >= zero_t)

    # The burst did arrive, after the deadman stop: the server answered every queued frame.
    deadline = time.monotonic() + 5
    while len(client.errors("stale_epoch")) < BURST_FRAMES:
        assert time.monotonic() < deadline, f"only {len(client.errors('stale_epoch'))} stale frames answered"
        time.sleep(0.02)
    # Every error is a dropped stale frame (frames still unread when the stall began count too).
    assert len(client.errors()) == len(client.errors("stale_epoch")) >= BURST_FRAMES
    state = client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "deadman")
    assert state["epoch"] == 1

    # A frame sent after the client heard of the stop is a live operator: the robot moves again.
    peer.clear("/cmd_vel")
    client.drive(0.6, 0.0)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(3.0), timeout=2.0)
    client.send({"stop": True})
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    return t_stall, t_unstall, zero_t


def test_network_stall_then_burst(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    proxy = StallingProxy(live_server.port)
    try:
        client = TeleopClient(proxy.url, name="wifi")
        t_stall, t_unstall, zero_t = drive_then_check_burst_was_refused(client, peer, proxy.pause, proxy.resume)
        # The server stopped the robot during the stall, by its deadman, not when the burst came.
        assert t_stall < zero_t < t_unstall
        client.close()
    finally:
        proxy.close()


def freeze(pid: int) -> None:
    """SIGSTOP, returning once every thread has stopped: kill() returns before they have, and a
    frame sent in that gap is read by a live server, rightly, as a live operator's."""
    os.kill(pid, signal.SIGSTOP)

    def stopped(tid: str) -> bool:
        try:
            with open(f"/proc/{pid}/task/{tid}/stat") as f:
                return f.read().rsplit(")", 1)[1].split()[0] in ("T", "t")
        except FileNotFoundError:
            return True  # a thread that ended cannot run
    wait_until(lambda: all(stopped(tid) for tid in os.listdir(f"/proc/{pid}/task")), 5, "server frozen", 0.001)


def test_server_stall_then_burst(server_process, ros_peer):
    server = server_process().start()
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    client = TeleopClient(server.url, name="frozen")
    pid = server.proc.pid
    try:
        t_stall, t_unstall, zero_t = drive_then_check_burst_was_refused(
            client, peer, lambda: freeze(pid), lambda: os.kill(pid, signal.SIGCONT))
        # A frozen server cannot publish: the stop came on waking, before it judged any queued frame.
        assert zero_t > t_unstall
    finally:
        os.kill(pid, signal.SIGCONT)
        client.close()
