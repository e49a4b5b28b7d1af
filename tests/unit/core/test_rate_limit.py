"""The sliding-window limit behind 429s for snapshots, panel unlocks and refused panel commands."""

import pytest

from rover_web.core import rate_limit
from rover_web.core.rate_limit import RateLimit


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self):
        return self.now


@pytest.fixture
def clock():
    return Clock()


def test_hits_beyond_the_count_wait_until_the_oldest_leaves_the_window(clock):
    limit = RateLimit(3, 60.0, clock=clock)
    for _ in range(3):
        assert limit.hit("ann") == 0.0
        clock.now += 10
    assert limit.hit("ann") == pytest.approx(30.0)  # the first hit, at 0 s, leaves at 60 s; now is 30 s
    assert limit.retry_after_s("ann") == pytest.approx(30.0)
    clock.now += 30
    assert limit.hit("ann") == 0.0  # a refused hit was not counted, so one slot is free again
    assert limit.hit("ann") == pytest.approx(10.0)


def test_keys_are_counted_apart(clock):
    limit = RateLimit(1, 60.0, clock=clock)
    assert limit.hit("ann") == 0.0
    assert limit.hit("bob") == 0.0
    assert limit.hit("ann") > 0


def test_record_counts_what_already_happened_and_retry_after_only_looks(clock):
    limit = RateLimit(2, 60.0, clock=clock)
    assert limit.retry_after_s("ann") == 0.0
    limit.record("ann")
    assert limit.retry_after_s("ann") == 0.0 and limit.retry_after_s("ann") == 0.0  # looking counts nothing
    limit.record("ann")
    assert limit.retry_after_s("ann") == pytest.approx(60.0)
    clock.now += 60
    assert limit.retry_after_s("ann") == 0.0


def test_the_table_of_keys_stays_bounded(clock, monkeypatch):
    monkeypatch.setattr(rate_limit, "MAX_TRACKED_KEYS", 100)
    limit = RateLimit(1, 60.0, clock=clock)
    for n in range(1000):
        limit.hit(f"client{n}")
        clock.now += 0.001
    assert len(limit._events) <= 100
    assert limit.hit("client999") > 0  # the newest are the ones kept
