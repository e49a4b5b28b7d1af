"""TeleopController rules with a fake clock and a recording output (no ROS, no threads)."""

import math

import pytest

from rover_web.teleop.commands import Limits, Refused, fraction, scale
from rover_web.teleop.control import INPUT_REPEAT_DELAY, TeleopController
from rover_web.teleop.repeater import Repeater

LIMITS = Limits(5.0, 2.0)


class Clock:
    def __init__(self):
        self.t = 100.0

    def __call__(self):
        return self.t

    def advance(self, dt):
        self.t += dt


class Output:
    """Stands in for rover.cmd_vel: records what would have been published, with the time."""

    def __init__(self, clock):
        self.clock = clock
        self.sent = []

    def send(self, linear, angular):
        self.sent.append((self.clock(), linear, angular))

    def zero(self):
        self.sent.append((self.clock(), 0.0, 0.0))

    @property
    def last(self):
        return self.sent[-1][1:]


@pytest.fixture
def rig():
    clock = Clock()
    out = Output(clock)
    states = []
    ctl = TeleopController(out, LIMITS, rate_hz=40, deadman_s=0.3, clock=clock, wall_clock=lambda: 1.7e9,
                           on_state=states.append)
    return ctl, clock, out, states


def run_until(ctl, clock, t_end):
    """Drive tick() the way the repeater thread does: wake exactly at the time it asks for."""
    while True:
        wake = ctl.tick()
        if wake is None or wake > t_end:
            clock.t = t_end
            ctl.tick()
            return
        clock.t = max(clock.t, wake)


def test_fraction_and_scale_clamp_and_refuse_non_finite():
    assert scale(0.5, -0.25, LIMITS) == (2.5, -0.5)
    assert scale(3, -7, LIMITS) == (5.0, -2.0)
    for bad in (math.nan, math.inf, -math.inf, "1", None, True, 10 ** 400, -10 ** 400):
        assert fraction(bad) == 0.0


def test_new_input_is_published_at_once_and_repeated_on_a_fixed_grid(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect("alice")
    assert ctl.drive(s, 0.5, 0.5) == (2.5, 1.0)
    assert out.sent == [(100.0, 2.5, 1.0)]  # no waiting for a tick
    for _ in range(7):  # keep-alives every 0.1 s with the same value: the repeater publishes
        run_until(ctl, clock, clock.t + 0.1)
        ctl.drive(s, 0.5, 0.5)
    run_until(ctl, clock, 100.701)
    times = [t for t, lin, _ in out.sent if lin == 2.5]
    gaps = [b - a for a, b in zip(times, times[1:], strict=False)]
    assert gaps[0] == pytest.approx(0.025 * INPUT_REPEAT_DELAY)  # the first repeat after the input
    assert all(abs(g - 0.025) < 1e-9 for g in gaps[1:]), gaps
    assert len(times) == 28  # the input, then 40 Hz from 30 ms after it


def test_changed_input_goes_out_immediately_and_restarts_the_grid(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 0.2, 0)
    clock.advance(0.01)
    ctl.drive(s, 0.4, 0)
    assert out.sent[-1] == (100.01, 2.0, 0.0)
    assert ctl.tick() == pytest.approx(100.01 + 0.025 * INPUT_REPEAT_DELAY)


def test_inputs_at_the_repeat_rate_are_not_doubled_by_repeats(rig):
    """A client sending at rate_hz, arriving up to 2 ms late or early: every input goes out, and
    no repeat of the previous value is squeezed in before it."""
    ctl, clock, out, _ = rig
    s = ctl.connect()
    jitter = [0.0, 0.002, -0.002, 0.0015, -0.001, 0.002]
    for i in range(40):
        run_until(ctl, clock, 100.0 + i * 0.025 + jitter[i % len(jitter)])
        ctl.drive(s, 0.1 + i * 0.01, 0)
    assert ctl.stats["repeated"] == 0
    assert [lin for _, lin, _ in out.sent] == [pytest.approx((0.1 + i * 0.01) * 5) for i in range(40)]


def test_deadman_stops_exactly_once_and_bumps_the_epoch(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 1, 0)
    run_until(ctl, clock, 101.0)
    zeros = [(t, lin) for t, lin, ang in out.sent if lin == 0.0]
    assert zeros == [(pytest.approx(100.3), 0.0)]
    assert out.sent[-1][1:] == (0.0, 0.0)
    assert all(t <= 100.3 for t, lin, _ in out.sent if lin)
    assert s.epoch == 1
    assert s.outbox[-1]["reason"] == "deadman" and s.outbox[-1]["epoch"] == 1
    assert ctl.state()["last_stop"]["reason"] == "deadman"


def test_frames_queued_during_a_stall_are_dropped_after_the_deadman(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 1, 0)
    clock.advance(1.0)  # the server itself stalled: the repeater never ran
    published = len(out.sent)
    for _ in range(20):  # the burst that piled up, all sent with epoch 0
        with pytest.raises(Refused) as info:
            ctl.drive(s, 1, 0, epoch=0)
        assert info.value.code == "stale_epoch"
    assert out.sent[published:] == [(101.0, 0.0, 0.0)]  # the lazy deadman's zero, nothing else
    assert ctl.stats["stale_dropped"] == 20
    # A frame sent after the client heard the new epoch is a live operator: it drives.
    assert ctl.drive(s, 1, 0, epoch=1) == (5.0, 0.0)


def test_operator_stop_does_not_bump_the_epoch(rig):
    ctl, clock, out, _ = rig
    s = ctl.connect()
    ctl.drive(s, 1, 0)
    assert ctl.stop(s)
    assert out.last == (0.0, 0.0) and s.epoch == 0
    assert ctl.tick() is None  # nothing held: the repeater sleeps
    ctl.drive(s, 0.2, 0)
    assert out.last == (1.0, 0.0)


def test_one_operator_at_a_time_takeover_and_disconnect(rig):
    ctl, clock, out, states = rig
    a, b = ctl.connect("alice"), ctl.connect("bob")
    ctl.drive(a, 0.5, 0)
    assert states[-1]["holder"] == {"id": a.id, "name": "alice"}
    with pytest.raises(Refused) as info:
        ctl.drive(b, -1, 0)
    assert info.value.code == "not_in_control" and "alice" in info.value.message
    assert out.last == (2.5, 0.0)
    assert not ctl.stop(b)  # a viewer's stop (its tab blurred) does not stop the holder
    assert out.last == (2.5, 0.0)
    ctl.takeover(b)
    assert out.last == (0.0, 0.0)  # whatever moved stops at the handover
    assert a.outbox[-1]["reason"] == "taken_over" and a.outbox[-1]["in_control"] is False
    assert a.epoch == 1
    with pytest.raises(Refused):
        ctl.drive(a, 0.5, 0, epoch=1)
    ctl.drive(b, -0.2, 0)
    assert out.last == (-1.0, 0.0)
    ctl.disconnect(b)
    assert out.last == (0.0, 0.0)
    assert ctl.state()["holder"] is None
    ctl.drive(a, 0.1, 0, epoch=1)  # control is free again
    assert out.last == (0.5, 0.0)


def test_release_frees_control_and_stops(rig):
    ctl, clock, out, _ = rig
    a, b = ctl.connect("a"), ctl.connect("b")
    ctl.drive(a, 1, 0)
    ctl.release(a)
    assert out.last == (0.0, 0.0) and ctl.state()["holder"] is None
    ctl.drive(b, 0.4, 0)
    assert out.last == (2.0, 0.0)


def test_estop_latch(rig):
    ctl, clock, out, states = rig
    a, _b = ctl.connect("a"), ctl.connect("b")
    ctl.drive(a, 1, 0)
    ctl.engage_estop("b")  # from a viewer: works whoever holds control
    assert out.last == (0.0, 0.0)
    assert states[-1]["estop"]["engaged"] is True
    for attempt in (lambda: ctl.drive(a, 1, 0, epoch=a.epoch), lambda: ctl.rest_command("forward", 1, 1)):
        with pytest.raises(Refused) as info:
            attempt()
        assert info.value.code == "estop_engaged" and info.value.status == 409
    assert ctl.tick() is None
    run_until(ctl, clock, 102)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in out.sent if t > 100)
    ctl.release_estop("b")
    ctl.stop(a)  # the stick released: re-armed
    assert ctl.drive(a, 1, 0, epoch=a.epoch) == (5.0, 0.0)


def test_an_input_held_through_a_release_does_not_drive_until_released_and_pressed_again(rig):
    ctl, clock, out, states = rig
    a = ctl.connect("a")
    ctl.drive(a, 1, 0)
    ctl.engage_estop("b")
    ctl.release_estop("b")
    assert a.outbox[-1]["reason"] == "estop_released" and a.outbox[-1]["armed"] is False
    published = len(out.sent)
    for _ in range(3):  # the page keeps sending the held stick
        with pytest.raises(Refused) as info:
            ctl.drive(a, 1, 0, epoch=a.epoch)
        assert info.value.code == "rearm_required" and "re-arm" in info.value.message
    assert len(out.sent) == published  # nothing went out
    ctl.drive(a, 0, 0, epoch=a.epoch)  # a neutral stick re-arms as well as a stop
    assert ctl.drive(a, 0.5, 0, epoch=a.epoch) == (2.5, 0.0)


def test_a_lost_link_stops_the_held_command_and_needs_a_neutral_input_to_drive_again(rig):
    """The robot's process died mid-drive: when it comes back, the stick held all along must not
    resume; the operator lets go and drives again."""
    ctl, clock, out, states = rig
    a = ctl.connect("a")
    ctl.drive(a, 1, 0)
    epoch = a.epoch
    ctl.link_lost()
    assert out.last == (0.0, 0.0) and a.epoch == epoch + 1
    assert a.outbox[-1]["reason"] == "link_lost" and a.outbox[-1]["armed"] is False
    run_until(ctl, clock, clock.t + 1.0)
    assert out.last == (0.0, 0.0)  # nothing repeats after the stop
    with pytest.raises(Refused) as info:
        ctl.drive(a, 1, 0, epoch=a.epoch)
    assert info.value.code == "rearm_required" and "link_lost" in info.value.message
    ctl.drive(a, 0, 0, epoch=a.epoch)
    assert ctl.drive(a, 0.5, 0, epoch=a.epoch) == (2.5, 0.0)


def test_a_lost_link_with_nothing_held_publishes_nothing(rig):
    ctl, clock, out, states = rig
    ctl.connect("a")
    ctl.link_lost()
    assert out.sent == []  # an idle GUI must not send zeros that would interrupt an autonomous goal


def test_a_socket_that_connects_after_the_release_is_armed(rig):
    ctl, clock, out, states = rig
    ctl.engage_estop("b")
    ctl.release_estop("b")
    late = ctl.connect("late")
    assert ctl.drive(late, 1, 0, epoch=late.epoch) == (5.0, 0.0)


def test_nobody_takes_control_while_the_e_stop_is_engaged(rig):
    ctl, clock, out, states = rig
    a, b = ctl.connect("a"), ctl.connect("b")
    ctl.drive(a, 1, 0)
    ctl.engage_estop("x")
    with pytest.raises(Refused) as info:
        ctl.takeover(b)
    assert info.value.code == "estop_engaged" and info.value.status == 409


def test_estop_restored_engaged():
    clock = Clock()
    ctl = TeleopController(Output(clock), LIMITS, clock=clock, estop={"engaged": True, "since": 1.0, "by": "x"})
    with pytest.raises(Refused):
        ctl.drive(ctl.connect(), 1, 0)


def test_rest_command_runs_for_its_duration_then_stops_by_itself(rig):
    ctl, clock, out, _ = rig
    assert ctl.rest_command("left", 0.5, 0.5) == (0.0, 1.0)
    run_until(ctl, clock, 101.0)
    moving = [t for t, lin, ang in out.sent if ang == 1.0]
    assert moving[0] == 100.0 and moving[-1] == pytest.approx(100.475)
    assert len(moving) == 20
    assert out.last == (0.0, 0.0)
    assert ctl.state()["last_stop"]["reason"] == "duration_elapsed"


def test_rest_is_refused_while_someone_holds_control_and_stop_always_wins(rig):
    ctl, clock, out, _ = rig
    a = ctl.connect("alice")
    ctl.drive(a, 1, 0)
    with pytest.raises(Refused) as info:
        ctl.rest_command("forward", 1, 1)
    assert info.value.code == "not_in_control"
    ctl.rest_stop()
    assert out.last == (0.0, 0.0)
    assert a.epoch == 1  # its queued frames cannot restart the robot
    ctl.engage_estop("x")
    ctl.rest_stop()  # works while the e-stop is engaged too
    assert out.last == (0.0, 0.0)


def test_a_joystick_input_replaces_a_running_rest_command(rig):
    ctl, clock, out, _ = rig
    ctl.rest_command("forward", 1, 5)
    a = ctl.connect()
    ctl.drive(a, 0, 0.5)
    assert out.last == (0.0, 1.0)
    run_until(ctl, clock, 100.29)
    assert {(lin, ang) for t, lin, ang in out.sent[1:]} == {(0.0, 1.0)}


def test_closed_controller_publishes_nothing(rig):
    ctl, clock, out, _ = rig
    a = ctl.connect()
    ctl.drive(a, 1, 0)
    n = len(out.sent)
    ctl.close()
    with pytest.raises(Refused):
        ctl.drive(a, 1, 0)
    ctl.disconnect(a)
    assert ctl.tick() is None
    assert len(out.sent) == n


def test_state_is_only_reported_when_it_changes(rig):
    ctl, clock, out, states = rig
    a = ctl.connect()
    ctl.drive(a, 1, 0)
    n = len(states)
    for _ in range(5):
        clock.advance(0.05)
        ctl.drive(a, 1, 0)
        ctl.tick()
    assert len(states) == n


def test_repeater_thread_wakes_on_time_and_exits_on_close():
    import threading
    import time

    class Recorder:
        def __init__(self):
            self.sent = []
            self.done = threading.Event()

        def send(self, linear, angular):
            self.sent.append((time.monotonic(), linear))

        def zero(self):
            self.sent.append((time.monotonic(), 0.0))
            self.done.set()

    out = Recorder()
    ctl = TeleopController(out, LIMITS, rate_hz=40, deadman_s=0.3)
    repeater = Repeater(ctl).start()
    try:
        s = ctl.connect()
        t0 = time.monotonic()
        ctl.drive(s, 1, 0)
        assert out.done.wait(5)
        stop_t = out.sent[-1][0]
        assert stop_t - t0 >= 0.3
        assert sum(1 for _, lin in out.sent if lin) >= 8  # repeated while held (about 12 at 40 Hz)
    finally:
        repeater.stop()
    assert not repeater.alive


def test_idle_stops_publish_nothing_but_explicit_stops_always_publish_zero(rig):
    """An idle page closing or blurring must not send zeros (they would interrupt an autonomous
    goal); a REST stop or the e-stop is a request to stop whatever moves the robot."""
    ctl, clock, out, _ = rig
    a = ctl.connect()
    ctl.drive(a, 0.5, 0)
    ctl.stop(a)
    n = len(out.sent)
    ctl.stop(a)
    ctl.release(a)
    b = ctl.connect()
    ctl.takeover(b)
    ctl.disconnect(b)
    assert len(out.sent) == n
    ctl.rest_stop()
    assert out.sent[n:] == [(100.0, 0.0, 0.0)]
    ctl.engage_estop("x")
    assert out.sent[n + 1:] == [(100.0, 0.0, 0.0)]


# --- the gamepad: one more source, under the same rules ---

def test_a_gamepad_source_is_recorded_and_logged_once_per_change(rig, caplog):
    ctl, clock, out, states = rig
    a = ctl.connect("alice")
    with caplog.at_level("INFO", logger="rover_web.teleop.control"):
        ctl.drive(a, 0.5, 0, source="gamepad")
        for _ in range(5):
            clock.advance(0.025)
            ctl.drive(a, 0.5, 0.1, source="gamepad")
        ctl.drive(a, 0.5, 0.1, source="joystick")
        ctl.drive(a, 0.5, 0.1, source="gamepad")
    assert states[-1]["source"] == "gamepad" and out.last == (2.5, 0.2)
    said = [r.getMessage() for r in caplog.records if r.name == "rover_web.teleop.control"]
    assert said == ["teleop: alice drives with the gamepad", "teleop: alice drives with the joystick",
                    "teleop: alice drives with the gamepad"]


def test_a_gamepad_gets_the_deadman_clamps_single_operator_estop_and_rearm_unchanged(rig):
    ctl, clock, out, states = rig
    a, b = ctl.connect("a"), ctl.connect("b")
    # Clamps: fractions scale by the maxima (values beyond [-1, 1] never reach here: protocol.py).
    assert ctl.drive(a, 1, -1, source="gamepad") == (5.0, -2.0)
    # Single operator: another socket's gamepad is refused while `a` holds control.
    with pytest.raises(Refused) as info:
        ctl.drive(b, 0.2, 0, source="gamepad")
    assert info.value.code == "not_in_control"
    # Deadman: silence stops the gamepad's command and bumps the epoch.
    run_until(ctl, clock, clock.t + 0.35)
    assert out.last == (0.0, 0.0) and a.epoch == 1 and states[-1]["last_stop"]["reason"] == "deadman"
    with pytest.raises(Refused) as info:
        ctl.drive(a, 1, 0, epoch=0, source="gamepad")
    assert info.value.code == "stale_epoch"
    # E-stop: refused while engaged; after the release a held stick must come back to neutral.
    ctl.drive(a, 0.4, 0, epoch=a.epoch, source="gamepad")
    ctl.engage_estop("b")
    with pytest.raises(Refused) as info:
        ctl.drive(a, 0.4, 0, epoch=a.epoch, source="gamepad")
    assert info.value.code == "estop_engaged"
    ctl.release_estop("b")
    with pytest.raises(Refused) as info:
        ctl.drive(a, 0.4, 0, epoch=a.epoch, source="gamepad")
    assert info.value.code == "rearm_required"
    ctl.drive(a, 0, 0, epoch=a.epoch, source="gamepad")
    assert ctl.drive(a, 0.4, 0, epoch=a.epoch, source="gamepad") == (2.0, 0.0)
    # Letting go of enable sends a stop: one zero, control kept.
    ctl.stop(a)
    assert out.last == (0.0, 0.0) and states[-1]["source"] is None and states[-1]["holder"]["name"] == "a"


def test_a_stop_with_a_seq_fences_off_older_drive_frames_that_arrive_after_it(rig):
    """The data channel is unordered: a drive frame sent just before the stop may arrive after it,
    and must not drive again."""
    ctl, clock, out, _ = rig
    session = ctl.connect("a")
    for seq in (1, 2, 3):
        ctl.drive(session, 0.2, 0.0, seq=seq)
    assert ctl.stop(session, "operator", seq=5) is True
    assert out.last == (0.0, 0.0)
    with pytest.raises(Refused) as late:
        ctl.drive(session, 0.2, 0.0, seq=4)  # sent before the stop, delivered after it
    assert late.value.code == "stale_seq"
    assert out.last == (0.0, 0.0) and not ctl.state()["moving"]
    ctl.drive(session, 0.3, 0.0, seq=6)  # input sent after the stop drives
    assert out.last == (1.5, 0.0)


def test_a_stop_older_than_an_admitted_frame_is_ignored(rig):
    """A repeated (or late) stop that the operator's newer input overtook does not stop that input."""
    ctl, clock, out, _ = rig
    session = ctl.connect("a")
    ctl.drive(session, 0.2, 0.0, seq=1)
    assert ctl.stop(session, "operator", seq=2) is True
    ctl.drive(session, 0.4, 0.0, seq=3)
    assert ctl.stop(session, "operator", seq=2) is False  # the stop's repeat, after the new press
    assert out.last == (2.0, 0.0) and ctl.state()["moving"]
    assert ctl.stop(session, "operator") is True  # without a seq (old clients): always a stop
    assert out.last == (0.0, 0.0)
    with pytest.raises(Refused):
        ctl.drive(session, 0.2, 0.0, seq=3)  # the floor stays at the highest seq seen
