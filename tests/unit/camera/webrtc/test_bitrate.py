"""When the encoder gets a new bitrate: in steps, so aiortc opens a new encoder (and sends a
keyframe) a few times a minute, not with every REMB."""

import random

from rover_web.camera.webrtc.bitrate import DOWN_INTERVAL_S, START_BPS, UP_HOLD_S, EncoderBitrate


class Clock:
    t = 0.0

    def __call__(self):
        return self.t


def test_it_climbs_at_once_until_the_first_push_back_and_small_moves_change_nothing():
    clock = Clock()
    rate = EncoderBitrate(clock=clock)
    assert rate.current == START_BPS == 500_000  # aiortc's own start
    assert rate.update(600_000) == 600_000  # a slow start: each climb taken as it comes
    clock.t += 0.2
    assert rate.update(700_000) == 700_000
    for wanted in (720_000, 680_000, 750_000, 610_000):
        clock.t += 0.3
        assert rate.update(wanted) == 700_000
    assert rate.changes == 2


def test_down_at_once_then_not_again_within_the_interval_unless_it_halves():
    clock = Clock()
    rate = EncoderBitrate(1_000_000, clock=clock)
    assert rate.update(800_000) == 800_000
    clock.t += 0.1
    assert rate.update(650_000) == 800_000  # lower again, too soon
    clock.t += DOWN_INTERVAL_S
    assert rate.update(650_000) == 650_000
    clock.t += 0.1
    assert rate.update(300_000) == 300_000  # a collapse (a stall) is followed at once
    assert rate.changes == 3


def test_after_a_push_back_up_only_once_the_estimate_stayed_higher_and_a_dip_restarts_the_wait():
    clock = Clock()
    rate = EncoderBitrate(600_000, clock=clock)
    assert rate.update(300_000) == 300_000  # the link pushed back: the slow start is over
    clock.t += 5
    assert rate.update(400_000) == 300_000
    clock.t += UP_HOLD_S - 0.5
    assert rate.update(420_000) == 300_000
    clock.t += 0.1
    assert rate.update(310_000) == 300_000  # back within the band: the wait starts over
    clock.t += 1.0
    assert rate.update(400_000) == 300_000
    clock.t += UP_HOLD_S + 0.01
    assert rate.update(410_000) == 410_000
    assert rate.changes == 2


def test_an_estimate_that_jitters_around_a_slow_climb_changes_the_encoder_a_few_times_a_minute():
    # REMB as the radio gave it: a packet every ~100 ms, ±8 % noise on a rate climbing 5 % a
    # second and cut to 85 % every 8 s. Passed on as it came, aiortc opened three encoders a second.
    clock, noise = Clock(), random.Random(1)
    rate = EncoderBitrate(300_000, clock=clock)
    estimate, naive = 300_000.0, 0
    last_naive = None
    for step in range(600):  # 60 s
        clock.t = step * 0.1
        estimate *= 1.005
        if step % 80 == 79:
            estimate *= 0.85
        wanted = int(estimate * noise.uniform(0.92, 1.08))
        if last_naive is None or abs(wanted - last_naive) > 0.1 * last_naive:
            naive += 1
        last_naive = wanted
        rate.update(wanted)
    assert naive > 60
    assert rate.changes <= 30
