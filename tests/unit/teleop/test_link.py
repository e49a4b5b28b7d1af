"""A teleop socket's link figures with a fake clock (link.py): round trip, jitter, stalls, seq, verdict."""

import json
import struct

import pytest

from rover_web.teleop.link import BASE_WINDOW_S, STALL_S, WINDOW_S, LinkMeter, verdict


class Clock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t

    def advance(self, dt):
        self.t += dt


@pytest.fixture
def rig():
    clock = Clock()
    return LinkMeter(clock), clock


def stream(meter, clock, n, period=0.05, send_ms=0.0, seq=1, transit=lambda i: 0.02):
    """n frames sent every `period` on the client's clock, each arriving after transit(i)."""
    sent0, t0 = send_ms, clock.t
    for i in range(n):
        clock.t = t0 + i * period + transit(i)
        meter.arrived(seq + i, sent0 + 1000 * i * period)
    return seq + n


def round_trip(meter, clock, seconds):
    payload = meter.ping()
    clock.advance(seconds)
    assert meter.pong(payload)
    return payload


def test_round_trip_from_pings_a_median_and_a_silent_link_shows_a_growing_one(rig):
    meter, clock = rig
    assert meter.snapshot()["rtt_ms"] is None
    round_trip(meter, clock, 0.080)
    assert meter.snapshot()["rtt_ms"] == 80.0
    payload = round_trip(meter, clock, 0.700)  # one spike: the lower median of two is the good one
    assert meter.snapshot()["rtt_ms"] == 80.0
    assert not meter.pong(payload)  # answered already
    for _ in range(3):  # a real change shows within three samples
        round_trip(meter, clock, 0.850)
    assert meter.snapshot()["rtt_ms"] == 850.0
    for _ in range(3):
        round_trip(meter, clock, 0.040)
    assert meter.snapshot()["rtt_ms"] == 40.0
    assert not meter.pong(struct.pack("!I", 9999)) and not meter.pong(b"") and not meter.pong(b"12345")
    meter.ping()
    clock.advance(0.9)  # no answer: the link went quiet
    snap = meter.snapshot()
    assert snap["rtt_ms"] == 900.0 and snap["quality"] == "too_poor" and snap["why"] == "900 ms round trip"


def test_pongs_come_in_order_so_older_open_pings_are_lost(rig):
    meter, clock = rig
    first = meter.ping()
    clock.advance(0.5)
    second = meter.ping()
    clock.advance(0.05)
    meter.pong(second)
    assert meter.snapshot()["rtt_ms"] == 50.0  # the unanswered first one no longer counts
    assert not meter.pong(first)


def test_jitter_is_zero_on_a_steady_link_and_follows_rfc_3550_on_a_jittery_one(rig):
    meter, clock = rig
    stream(meter, clock, 40)
    snap = meter.snapshot()
    assert snap["jitter_ms"] == 0.0 and snap["quality"] == "ok" and snap["stalls"] == 0
    meter2 = LinkMeter(clock)
    stream(meter2, clock, 200, transit=lambda i: 0.02 + 0.1 * (i % 2))  # every transit differs by 100 ms
    assert meter2.snapshot()["jitter_ms"] == pytest.approx(100.0, abs=0.5)
    j, expected = LinkMeter(clock), 0.0
    stream(j, clock, 3, transit=lambda i: 0.02 + 0.016 * (i % 2))
    for _ in range(2):
        expected += (16.0 - expected) / 16
    assert j.snapshot()["jitter_ms"] == pytest.approx(expected, abs=0.05)


def test_a_stall_is_an_arrival_gap_the_send_times_do_not_explain(rig):
    meter, clock = rig
    seq = stream(meter, clock, 10)
    # The next frames were sent on time, but all of them arrive 400 ms late, in one burst.
    base = clock.t
    for i in range(8):
        clock.t = base + 0.4
        meter.arrived(seq + i, 1000 * 0.05 * (10 + i))
    snap = meter.snapshot()
    assert snap["stalls"] == 1 and snap["last_stall_ms"] == pytest.approx(400 - 50 + 20 - 20, abs=25)
    assert snap["quality"] == "poor" and "stall" in snap["why"]
    # A client that paused itself (its send times jump too) is no stall.
    pause = LinkMeter(clock)
    stream(pause, clock, 5)
    clock.advance(1.0)
    pause.arrived(6, 1000 * (0.05 * 5 + 1.0))
    assert pause.snapshot()["stalls"] == 0
    # Without send times, only arrival gaps are known.
    blind = LinkMeter(clock)
    blind.arrived()
    clock.advance(STALL_S + 0.1)
    blind.arrived()
    assert blind.snapshot()["stalls"] == 1
    # After the operator lets go, silence is theirs.
    blind.idle()
    clock.advance(5)
    blind.arrived()
    assert blind.snapshot()["stalls"] == 1
    clock.advance(WINDOW_S + 1)
    assert blind.snapshot()["stalls"] == 0 and blind.snapshot()["last_stall_ms"] == 0


def test_seq_gaps_are_lost_frames_and_older_frames_are_out_of_order(rig):
    meter, clock = rig
    assert meter.arrived(5, None) == 0.0
    assert meter.arrived(8, None) == 0.0  # 6 and 7 never came
    assert meter.arrived(7, None) is None and meter.arrived(8, None) is None  # late, and a repeat
    assert meter.arrived(9, None) == 0.0
    assert meter.arrived(None, None) == 0.0  # a frame without seq is not ordered
    snap = meter.snapshot()
    assert (snap["lost"], snap["out_of_order"]) == (2, 2)


def test_loss_counts_in_the_verdict_once_there_are_enough_frames(rig):
    meter, clock = rig
    for i in range(30):
        clock.advance(0.025)
        meter.arrived(1 + 2 * i, None)  # every other frame lost
    snap = meter.snapshot()
    assert snap["lost"] == 29 and snap["quality"] == "too_poor" and "frames lost" in snap["why"]


def test_lateness_is_transit_beyond_the_best_recent_one(rig):
    meter, clock = rig
    assert meter.arrived(1, 0.0) == 0.0
    clock.advance(0.05 + 0.3)  # sent 50 ms after the first, arrives 300 ms later than it would have
    assert meter.arrived(2, 50.0) == pytest.approx(0.3)
    clock.advance(0.0)
    assert meter.arrived(3, 350.0) == pytest.approx(0.0)  # sent just now: on time
    # A client clock that jumps ahead makes a frame look early, never earlier than its arrival.
    assert meter.arrived(4, 1e9) == 0.0
    # The best transit is forgotten after BASE_WINDOW_S, so a lasting change of route is too.
    clock.advance(BASE_WINDOW_S + 1)
    sent = 350.0 + 1000 * (BASE_WINDOW_S + 1) - 500  # from now on every frame takes 500 ms longer
    meter.arrived(5, sent)
    clock.advance(0.05)
    assert meter.arrived(6, sent + 50) == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize("figures, quality, why", [
    ((40, 5, 0, 0.0), "ok", ""),
    ((None, None, 0, 0.0), "ok", ""),
    ((300, 5, 0, 0.0), "poor", "300 ms round trip"),
    ((40, 60, 0, 0.0), "poor", "60 ms jitter"),
    ((40, 5, 400, 0.0), "poor", "a 400 ms stall"),
    ((40, 5, 0, 0.05), "poor", "5 % of frames lost"),
    ((850, 5, 0, 0.0), "too_poor", "850 ms round trip"),
    ((300, 200, 0, 0.0), "too_poor", "200 ms jitter"),
    ((40, 5, 1200, 0.0), "too_poor", "a 1200 ms stall"),
])
def test_verdict(figures, quality, why):
    assert verdict(*figures) == (quality, why)


def test_a_snapshot_is_plain_json_with_the_fields_the_page_shows(rig):
    meter, clock = rig
    stream(meter, clock, 5)
    snap = meter.snapshot()
    json.dumps(snap, allow_nan=False)
    assert {"rtt_ms", "jitter_ms", "stalls", "last_stall_ms", "quality"} <= set(snap)


def test_fence_raises_the_seq_floor_and_refuses_what_is_not_newer():
    meter = LinkMeter(lambda: 0.0)
    assert meter.admit(1, None, 0.0) == 0.0
    assert meter.fence(None) is True   # no seq: the floor is the highest seen already
    assert meter.admit(1, None, 0.0) is None
    assert meter.fence(4) is True
    assert meter.admit(3, None, 0.0) is None and meter.admit(4, None, 0.0) is None
    assert meter.fence(4) is False     # a repeat of that stop
    assert meter.admit(5, None, 0.0) == 0.0
    assert meter.fence(3) is False
    assert meter.lost == 2             # 2 and 3 never came before the fence at 4
