"""The controller on a jittery link, with a fake clock: hold, ramp, hard bound, resume, order, lateness.

deadman_s (the hold) is 0.3 s and deadman_max_s (the hard bound) 1.0 s, as the app's defaults.
"""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.teleop.commands import Limits, Refused
from rover_web.teleop.control import TeleopController
from tests.unit.teleop.test_control import Clock, Output, run_until

LIMITS = Limits(5.0, 2.0)
HOLD, BOUND = 0.3, 1.0


@pytest.fixture
def rig():
    clock = Clock()
    out = Output(clock)
    states = []
    ctl = TeleopController(out, LIMITS, rate_hz=40, deadman_s=HOLD, deadman_max_s=BOUND, clock=clock,
                           wall_clock=lambda: 1.7e9, on_state=states.append)
    return ctl, clock, out, states


def after(out, t):
    return [(tt, lin, ang) for tt, lin, ang in out.sent if tt > t]


def test_silence_holds_then_ramps_down_then_stops_once_at_the_hard_bound(rig):
    ctl, clock, out, states = rig
    s = ctl.connect()
    ctl.drive(s, 0.8, 0.5)  # 4.0 m/s, 1.0 rad/s
    t0 = clock.t
    run_until(ctl, clock, t0 + 2.0)
    held = [(t, lin, ang) for t, lin, ang in out.sent if t < t0 + HOLD]
    ramp = [(t, lin, ang) for t, lin, ang in out.sent if t0 + HOLD < t < t0 + BOUND]
    zeros = [t for t, lin, ang in out.sent if lin == 0.0 and ang == 0.0]
    assert {(lin, ang) for _, lin, ang in held} == {(4.0, 1.0)}
    assert len(ramp) >= 20  # 0.7 s of ramp at 40 Hz
    speeds = [lin for _, lin, _ in ramp]
    assert all(0 < v < 4.0 for v in speeds) and speeds == sorted(speeds, reverse=True)
    assert all(ang / lin == pytest.approx(0.25) for _, lin, ang in ramp)  # the same arc, slower
    for t, lin, _ in ramp:  # linear from the held speed at the hold to zero at the bound
        assert lin == pytest.approx(4.0 * (t0 + BOUND - t) / (BOUND - HOLD))
    assert zeros == [pytest.approx(t0 + BOUND)]  # one zero, at the bound, and nothing after it
    assert out.sent[-1][1:] == (0.0, 0.0)
    assert s.epoch == 1 and s.outbox[-1]["reason"] == "deadman"
    assert any(st["ramping"] for st in states) and states[-1]["ramping"] is False
    assert ctl.state()["last_stop"]["reason"] == "deadman"


def test_a_fresh_frame_during_the_ramp_resumes_at_once_without_a_stop_or_a_new_epoch(rig):
    ctl, clock, out, states = rig
    s = ctl.connect()
    ctl.drive(s, 0.8, 0, seq=1, sent_ms=0)
    t0 = clock.t
    run_until(ctl, clock, t0 + 0.6)  # a 600 ms stall: the hold is over, the ramp half way
    assert 0 < out.last[0] < 4.0 and ctl.state()["ramping"]
    n = len(out.sent)
    ctl.drive(s, 0.8, 0, seq=2, sent_ms=600)  # the same value, sent just now: at once, at full speed
    assert out.sent[n:] == [(t0 + 0.6, 4.0, 0.0)]
    assert s.epoch == 0 and not any(m["reason"] == "deadman" for m in s.outbox)
    assert ctl.state()["ramping"] is False
    run_until(ctl, clock, t0 + 0.6 + HOLD - 0.01)
    assert {lin for _, lin, _ in after(out, t0 + 0.6)} == {4.0}  # held again, on the grid
    assert not any(lin == 0.0 for _, lin, _ in out.sent)


def test_a_stall_that_ends_in_a_burst_resumes_and_the_newest_frame_wins(rig):
    """What a 400 ms TCP stall does: frames sent during it arrive together when it ends."""
    ctl, clock, out, _ = rig
    s = ctl.connect()
    for i in range(10):  # 40 Hz, 20 ms transit
        clock.t = 100.0 + i * 0.025 + 0.02
        ctl.drive(s, 0.5, 0, seq=i, sent_ms=i * 25)
    last_fresh = clock.t
    run_until(ctl, clock, last_fresh + 0.4)
    for i in range(10, 26):  # the 400 ms of frames held in the stall, the stick pushed further
        ctl.drive(s, 0.6, 0, seq=i, sent_ms=i * 25)
    assert out.last == (3.0, 0.0)  # the newest one, sent just now, at full speed
    assert s.epoch == 0 and not any(lin == 0.0 for _, lin, _ in out.sent)
    burst = [lin for t, lin, _ in out.sent if t == clock.t]
    assert max(burst) == 3.0 and all(lin <= 3.0 for lin in burst)


def test_frames_older_than_the_newest_seen_are_dropped_and_never_override_it(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 0.2, 0, seq=7)
    n = len(out.sent)
    for old in (7, 6, 0):
        with pytest.raises(Refused) as info:
            ctl.drive(s, 1.0, 0, seq=old)
        assert info.value.code == "stale_seq"
    assert len(out.sent) == n and ctl.state()["linear_mps"] == 1.0
    assert ctl.stats["out_of_order_dropped"] == 3
    ctl.drive(s, 0.4, 0, seq=9)  # 8 was lost: the next newer frame drives
    assert out.last == (2.0, 0.0)
    assert s.link.snapshot()["lost"] == 1 and s.link.snapshot()["out_of_order"] == 3


def test_a_stale_seq_frame_does_not_rearm_after_an_estop_release(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 0.5, 0, seq=5)
    ctl.engage_estop("x")
    ctl.release_estop("x")
    with pytest.raises(Refused) as info:
        ctl.drive(s, 0, 0, epoch=s.epoch, seq=4)  # an old neutral frame
    assert info.value.code == "stale_seq"
    with pytest.raises(Refused) as info:
        ctl.drive(s, 0.5, 0, epoch=s.epoch, seq=6)
    assert info.value.code == "rearm_required"


def test_a_frame_that_waited_in_a_buffer_is_dated_from_when_it_was_sent(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 0.5, 0, seq=1, sent_ms=0)  # the best transit: the reference
    clock.advance(0.05)
    ctl.drive(s, 0.5, 0, seq=2, sent_ms=50)
    t_sent = clock.t
    clock.advance(0.65)  # the next frame was sent now-0.65+0.05 but spent 0.6 s in a stalled buffer
    ctl.drive(s, 0.5, 0, seq=3, sent_ms=100)
    # Its input is 0.6 s old: half way down the ramp at once, not a fresh second of motion.
    assert out.last[0] == pytest.approx(2.5 * (BOUND - 0.6) / (BOUND - HOLD))
    run_until(ctl, clock, t_sent + 0.05 + BOUND - 0.001)
    assert out.last[0] > 0
    run_until(ctl, clock, t_sent + 0.05 + BOUND + 0.001)
    assert out.last == (0.0, 0.0) and s.epoch == 1  # the bound counts from its sending
    # One so late that its input is past the bound is not driven by at all.
    n = len(out.sent)
    with pytest.raises(Refused) as info:  # transit 1.2 s beyond the first frame's
        ctl.drive(s, 0.9, 0, epoch=s.epoch, seq=4, sent_ms=1000 * (clock.t - 100.0 - 1.2))
    assert info.value.code == "late_frame" and "1200 ms late" in info.value.message
    assert out.sent[n:] == [] and ctl.stats["late_dropped"] == 1


def test_a_steady_stream_of_frames_each_later_than_the_last_still_stops_at_the_bound(rig):
    """Frames keep coming, but the link falls behind (each sent 25 ms after the previous one,
    each arriving 100 ms after it): the input they carry ages, so the robot stops all the same."""
    ctl, clock, out, _ = rig
    s = ctl.connect()
    t0 = clock.t
    refused = []
    for i in range(40):
        clock.t = t0 + 0.1 * i
        run_until(ctl, clock, clock.t)
        try:
            ctl.drive(s, 0.5, 0, epoch=0, seq=i, sent_ms=25 * i)
        except Refused as exc:
            refused.append(exc.code)
    first_zero = next(t for t, lin, ang in out.sent if lin == 0 and ang == 0)
    # Frame i's input is 0.075 i old on arrival; it reaches the bound by frame 14 (at t0 + 1.4 s).
    assert first_zero <= t0 + 1.4 + 1e-9
    assert refused and set(refused) <= {"stale_epoch", "late_frame"}


@pytest.mark.parametrize("stop", ["disconnect", "estop", "operator", "link_lost", "takeover", "release"])
def test_every_other_stop_is_at_once_even_during_the_hold_or_the_ramp(rig, stop):
    ctl, clock, out, _ = rig
    s, other = ctl.connect("a"), ctl.connect("b")
    ctl.drive(s, 0.5, 0)
    run_until(ctl, clock, clock.t + 0.5)  # ramping
    assert 0 < out.last[0] < 2.5
    t = clock.t
    {"disconnect": lambda: ctl.disconnect(s), "estop": lambda: ctl.engage_estop("x"),
     "operator": lambda: ctl.stop(s), "link_lost": ctl.link_lost,
     "takeover": lambda: ctl.takeover(other), "release": lambda: ctl.release(s)}[stop]()
    assert out.sent[-1] == (t, 0.0, 0.0)
    run_until(ctl, clock, t + 2)
    assert [x for x in out.sent if x[0] >= t] == [(t, 0.0, 0.0)]


def test_rest_commands_keep_their_own_deadline_without_a_ramp(rig):
    ctl, clock, out, _ = rig
    ctl.rest_command("forward", 0.5, 1.5)
    run_until(ctl, clock, 102.0)
    moving = [lin for t, lin, _ in out.sent if t < 101.5]
    assert set(moving) == {2.5}
    assert out.sent[-1] == (pytest.approx(101.5), 0.0, 0.0)


def test_a_bound_below_the_hold_means_hold_then_stop():
    clock = Clock()
    out = Output(clock)
    ctl = TeleopController(out, LIMITS, deadman_s=0.5, deadman_max_s=0.2, clock=clock)
    assert ctl.deadman_max_s == 0.5
    ctl.drive(ctl.connect(), 1, 0)
    run_until(ctl, clock, 101)
    assert {lin for t, lin, _ in out.sent if t < 100.5} == {5.0}
    assert [t for t, lin, _ in out.sent if lin == 0] == [pytest.approx(100.5)]


def test_state_frames_carry_the_link(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    message = ctl.session_state(s, "link")
    assert message["link"]["quality"] == "ok" and message["reason"] == "link"
    assert ctl.state()["deadman_max_s"] == BOUND


# --- property: whatever the frames and the timing, the output stays finite, bounded and stops ---

events = st.lists(st.one_of(
    st.tuples(st.just("drive"), st.floats(-1, 1), st.floats(-1, 1), st.integers(0, 30),
              st.one_of(st.none(), st.floats(0, 5000))),
    st.tuples(st.just("wait"), st.floats(0, 0.6)),
    st.tuples(st.just("stop")),
), max_size=30)


@settings(max_examples=300, deadline=None)
@given(events=events)
def test_any_frames_at_any_times_publish_finite_values_within_the_last_command_and_stop_by_the_bound(events):
    clock = Clock()
    out = Output(clock)
    ctl = TeleopController(out, LIMITS, rate_hz=40, deadman_s=HOLD, deadman_max_s=BOUND, clock=clock)
    s = ctl.connect()
    last_accepted = None  # (arrival, command)
    for event in events:
        if event[0] == "drive":
            _, lin, ang, seq, sent = event
            try:
                cmd = ctl.drive(s, lin, ang, epoch=s.epoch, seq=seq, sent_ms=sent)
                last_accepted = (clock.t, cmd)
            except Refused:
                pass
        elif event[0] == "wait":
            run_until(ctl, clock, clock.t + event[1])
        else:
            ctl.stop(s)
            last_accepted = None
        if last_accepted:
            lin, ang = out.last
            assert abs(lin) <= abs(last_accepted[1][0]) + 1e-12 and abs(ang) <= abs(last_accepted[1][1]) + 1e-12
    end = clock.t
    run_until(ctl, clock, end + BOUND + 0.05)
    assert all(math.isfinite(lin) and math.isfinite(ang) for _, lin, ang in out.sent)
    assert all(abs(lin) <= 5.0 and abs(ang) <= 2.0 for _, lin, ang in out.sent)
    if out.sent:
        assert out.last == (0.0, 0.0)  # silent for the bound: zero, whatever came before
        assert all(lin == 0 and ang == 0 for t, lin, ang in out.sent if t >= end + BOUND)
