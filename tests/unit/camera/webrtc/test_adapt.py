"""The step-down policy: quick down when the bitrate stays low, slow up with headroom, no flapping."""

import pytest

from rover_web.camera.webrtc.adapt import DOWN_AFTER_S, LEVELS, UP_AFTER_S, UP_HEADROOM, AdaptPolicy, even


class Clock:
    def __init__(self):
        self.t = 10.0

    def __call__(self):
        return self.t


@pytest.fixture
def policy():
    clock = Clock()
    return AdaptPolicy(30.0, clock=clock), clock


def run(policy, clock, bps, seconds, step=0.1, size=(640, 480)):
    out = None
    for _ in range(round(seconds / step)):
        out = policy.update(bps, *size)
        clock.t += step
    return out


def test_full_rate_and_size_while_the_bitrate_suffices(policy):
    p, clock = policy
    out = run(p, clock, 1_500_000, 10)
    assert (out.width, out.height, out.fps, out.level) == (640, 480, 30.0, 0)
    assert p.changes == 0


def test_unknown_bitrate_keeps_the_level(policy):
    p, clock = policy
    assert run(p, clock, None, 10).level == 0


def test_steps_down_frame_rate_first_then_size_then_rate_again(policy):
    p, clock = policy
    need0 = p.needs_bps(0, 640, 480)
    assert need0 == pytest.approx(0.05 * 640 * 480 * 30)
    out = run(p, clock, 30_000, DOWN_AFTER_S + 0.3)
    assert (out.width, out.height, out.level) == (640, 480, 1) and out.fps == pytest.approx(20.0)
    out = run(p, clock, 30_000, DOWN_AFTER_S + 0.3)
    assert (out.width, out.height, out.fps, out.level) == (640, 480, 15.0, 2)
    out = run(p, clock, 30_000, DOWN_AFTER_S + 0.3)
    assert (out.width, out.height, out.fps, out.level) == (320, 240, 15.0, 3)
    out = run(p, clock, 30_000, DOWN_AFTER_S + 0.3)
    assert (out.width, out.height, out.level) == (320, 240, 4) and out.fps == pytest.approx(10.0)
    out = run(p, clock, 30_000, 10)  # the floor: nothing lower
    assert out.level == len(LEVELS) - 1


def test_a_short_dip_does_not_step_down(policy):
    p, clock = policy
    run(p, clock, 100_000, DOWN_AFTER_S * 0.8)
    run(p, clock, 2_000_000, 0.2)  # recovered before the dip lasted long enough
    assert run(p, clock, 100_000, DOWN_AFTER_S * 0.8).level == 0


def test_recovers_only_with_headroom_held_for_a_while(policy):
    p, clock = policy
    run(p, clock, 30_000, 4 * (DOWN_AFTER_S + 0.3))
    assert p.level == 4
    up_to_3 = p.needs_bps(3, 640, 480)
    # Just enough for level 3, but without the headroom: stays.
    assert run(p, clock, up_to_3 * 1.01, UP_AFTER_S * 3).level == 4
    # With the headroom, but not for long enough: stays.
    assert run(p, clock, up_to_3 * UP_HEADROOM, UP_AFTER_S * 0.8).level == 4
    assert run(p, clock, up_to_3 * UP_HEADROOM, UP_AFTER_S * 0.3).level == 3
    # A good link brings it all the way back, one level per UP_AFTER_S.
    out = run(p, clock, 5_000_000, 3 * UP_AFTER_S + 0.5)
    assert (out.width, out.height, out.fps, out.level) == (640, 480, 30.0, 0)


def test_a_link_wavering_around_one_threshold_does_not_flap(policy):
    p, clock = policy
    need0 = p.needs_bps(0, 640, 480)
    for _ in range(20):
        run(p, clock, need0 * 0.95, 0.5)
        run(p, clock, need0 * 1.05, 0.5)
    assert p.changes <= 1


def test_sizes_stay_even_for_4_2_0_video():
    assert even(321) == 320 and even(1) == 2 and even(240.5) == 240
    clock = Clock()
    p = AdaptPolicy(30.0, clock=clock)
    out = run(p, clock, 1, 5 * (DOWN_AFTER_S + 0.3), size=(642, 362))
    assert out.width % 2 == 0 and out.height % 2 == 0 and (out.width, out.height) == (320, 180)
