"""Sign-in throttling on a clock the test controls."""

from rover_web.auth.throttle import MAX_TRACKED_NAMES, LoginThrottle


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self):
        return self.now


def test_five_failures_within_a_minute_lock_the_name_for_a_minute():
    clock = Clock()
    throttle = LoginThrottle(clock=clock)
    for _ in range(4):
        throttle.failed("ada")
        clock.now += 10
    assert throttle.retry_after_s("ada") == 0
    throttle.failed("ada")
    assert 59 < throttle.retry_after_s("ada") <= 60
    assert throttle.retry_after_s("bob") == 0  # other names are not locked with it
    clock.now += 60.01
    assert throttle.retry_after_s("ada") == 0


def test_failures_spread_over_more_than_the_window_do_not_lock():
    clock = Clock()
    throttle = LoginThrottle(clock=clock)
    for _ in range(10):
        throttle.failed("ada")
        clock.now += 15.1  # at most four inside any 60 s window
    assert throttle.retry_after_s("ada") == 0


def test_a_success_clears_the_count():
    clock = Clock()
    throttle = LoginThrottle(clock=clock)
    for _ in range(4):
        throttle.failed("ada")
    throttle.succeeded("ada")
    throttle.failed("ada")
    assert throttle.retry_after_s("ada") == 0


def test_attacker_chosen_names_cannot_grow_the_table_without_bound():
    clock = Clock()
    throttle = LoginThrottle(clock=clock)
    for i in range(MAX_TRACKED_NAMES * 3):
        throttle.failed(f"name{i}")
    assert len(throttle._failures) <= MAX_TRACKED_NAMES
