"""Teleop on a jittery link, against a real rclpy subscriber in another process: a short gap or
stall does not make a held stick stutter, a silent one still stops by the hard bound, late frames
never override newer ones, and the socket's `state` frames carry the measured link.

Every timing below is a bound with a generous margin, not a benchmark (bench/teleop.py measures).
"""

import time

import pytest

from rover_web.linkemu import LinkEmulator, profile
from rover_web.teleop.link import QUALITIES
from tests.support.teleop_support import StallingProxy, TeleopClient, is_zero, subscribe_cmd_vel, twists, warm_up


@pytest.fixture
def rig(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    return live_server, peer


def long_link(delay_ms: float):
    """Only a one-way delay, changeable live (LinkEmulator.set_profile): no cap worth the name, a
    deep buffer, no jitter, loss, stalls or outages (bench/link.py's loopback control, delayed)."""
    return profile("custom", rate_kbps=1_000_000, buffer_kb=4096, delay_ms=delay_ms)


class Page:
    """Sends drive frames as the Drive card does: every one numbered and stamped with its send time."""

    def __init__(self, client: TeleopClient):
        self.client = client
        self.seq = 0

    def drive(self, linear: float, t_ms: float | None = None, seq: int | None = None) -> float:
        self.seq += 1
        return self.client.drive(linear, 0.0, seq=self.seq if seq is None else seq,
                                 t=time.monotonic() * 1000 if t_ms is None else t_ms)

    def hold(self, linear: float, seconds: float, rate_hz: float = 40.0) -> list[float]:
        period, start, times = 1.0 / rate_hz, time.monotonic(), []
        for i in range(round(seconds * rate_hz)):
            delay = start + i * period - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            times.append(self.drive(linear))
        return times


def link_states(client, after: float = 0.0) -> list[dict]:
    return [m for m in client.messages if m["type"] == "state" and m.get("reason") == "link" and m["t"] > after]


def test_a_200_ms_pause_in_a_held_sticks_frames_keeps_it_moving_without_a_stop(rig):
    server, peer = rig
    page = Page(TeleopClient(server.url, name="pause"))
    page.hold(0.5, 0.5)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.5, timeout=2.0)
    time.sleep(0.2)  # the page's frames pause (a busy main thread, a short radio fade)
    page.hold(0.5, 0.5)
    page.client.send({"stop": True})
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    moving = [lin for t, lin, _ in twists(peer) if t < zero["t"]]
    assert moving and all(0 < lin <= 2.5 for lin in moving)  # held (or eased), never zero, never more
    assert not any(m["type"] == "state" and m["reason"] == "deadman" for m in page.client.messages)
    assert page.client.epoch == 0 and not page.client.errors()
    page.client.close()


def test_a_400_ms_tcp_stall_is_ridden_out_and_shows_in_the_link(live_server, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    proxy = StallingProxy(live_server.port)
    try:
        page = Page(TeleopClient(proxy.url, name="wifi-edge"))
        page.hold(0.5, 0.5)
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.5, timeout=2.0)
        proxy.pause()  # both ways, as a TCP retransmission does; the page keeps sending
        t_stall = time.monotonic()
        page.hold(0.5, 0.4)
        proxy.resume()
        page.hold(0.5, 0.5)
        page.client.send({"stop": True})
        zero = peer.wait_for("/cmd_vel", lambda m: is_zero(m), timeout=2.0)
        during = [lin for t, lin, _ in twists(peer) if t_stall <= t < zero["t"]]
        assert during and all(0 < lin <= 2.5 for lin in during)  # it eased off at most, never stopped
        assert not any(m["type"] == "state" and m["reason"] == "deadman" for m in page.client.messages)
        assert page.client.epoch == 0 and not page.client.errors()
        # The next link report tells of the stall.
        t_resumed = time.monotonic()
        report = page.client.wait_for(lambda m: m["type"] == "state" and m.get("reason") == "link"
                                      and m["t"] > t_resumed and m["link"]["stalls"] >= 1)["link"]
        assert report["last_stall_ms"] >= 200 and report["quality"] in ("poor", "too_poor")
        page.client.close()
    finally:
        proxy.close()


def test_a_stick_that_goes_silent_is_at_zero_within_the_hard_bound(rig):
    server, peer = rig
    client = TeleopClient(server.url)
    page = Page(client)
    bound_s = client.hello["deadman_max_s"]
    t_last = page.hold(0.6, 0.5)[-1]
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=5.0)
    assert zero["t"] - t_last <= bound_s + 0.5, zero["t"] - t_last  # a bound, with a generous margin
    time.sleep(0.5)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    assert client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "deadman")["epoch"] == 1
    client.close()


def test_a_frame_older_than_the_newest_is_dropped_and_never_overrides_it(rig):
    server, peer = rig
    client = TeleopClient(server.url)
    page = Page(client)
    page.drive(0.4, seq=10)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 2.0, timeout=2.0)
    page.drive(0.9, seq=9)  # sent before the one that came first
    assert client.wait_errors(1)[0]["error"] == "stale_seq"
    page.drive(0.2, seq=11)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 1.0, timeout=2.0)
    assert all(lin != 4.5 for _, lin, _ in twists(peer))
    client.send({"stop": True})
    client.close()


def test_state_frames_carry_the_link_twice_a_second(rig):
    server, peer = rig
    client = TeleopClient(server.url)  # websocket-client answers the measuring pings, as browsers do
    assert {"rtt_ms", "jitter_ms", "stalls", "last_stall_ms", "quality"} <= set(client.hello["link"])
    Page(client).hold(0.0, 1.0)  # neutral frames: measured, nothing moves
    t0 = time.monotonic()
    client.wait_for(lambda m: len(link_states(client, t0)) >= 2)
    report = client.wait_for(lambda m: m.get("reason") == "link" and m["link"]["rtt_ms"] is not None
                             and m["link"]["jitter_ms"] is not None)["link"]
    assert report["rtt_ms"] >= 0 and report["jitter_ms"] is not None and report["quality"] in QUALITIES
    client.close()


def test_frames_whose_send_times_jitter_by_300_ms_make_the_link_too_poor(rig):
    """A client whose frames' transit swings by 300 ms from one to the next (their `t`): the
    server's own RFC 3550 estimate says so, through the real socket."""
    server, peer = rig
    client = TeleopClient(server.url)
    page = Page(client)
    start = time.monotonic()
    for i in range(60):
        time.sleep(max(0.0, start + i * 0.025 - time.monotonic()))
        page.drive(0.0, t_ms=(time.monotonic() - 0.3 * (i % 2)) * 1000)
    report = client.wait_for(lambda m: m.get("reason") == "link" and m["link"]["quality"] == "too_poor")["link"]
    assert report["jitter_ms"] >= 150 and "jitter" in report["why"]
    assert all(lin == 0.0 for _, lin, _ in twists(peer))
    client.close()


def test_a_long_round_trip_makes_the_link_too_poor(live_server):
    with LinkEmulator(long_link(0), "127.0.0.1:0", ("127.0.0.1", live_server.port)) as link:
        client = TeleopClient(f"http://127.0.0.1:{link.port}")
        link.set_profile(long_link(450))  # each way
        report = client.wait_for(lambda m: m.get("reason") == "link" and (m["link"]["rtt_ms"] or 0) >= 800,
                                 timeout=20)["link"]
        assert report["quality"] == "too_poor" and "round trip" in report["why"]
        client.close()
