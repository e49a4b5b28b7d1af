"""Sign-in throttling on a clock the test controls, and the bound on concurrent hashes."""

import threading

import pytest

from rover_web.auth.throttle import (
    FREE_FAILURES_PER_ADDRESS,
    FREE_FAILURES_PER_NAME,
    MAX_DELAY_S,
    MAX_TRACKED_KEYS,
    HashGate,
    HashingBusy,
    SignInThrottle,
)


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self):
        return self.now


def fail(throttle, name, address, times, clock):
    for _ in range(times):
        wait, _ = throttle.admit(name, address)
        assert wait == 0
        throttle.failed(name, address)


def test_failures_for_a_name_back_off_exponentially_from_that_address_only():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=1000, clock=clock)
    fail(throttle, "ada", "10.0.0.1", FREE_FAILURES_PER_NAME, clock)
    wait, why = throttle.admit("ada", "10.0.0.1")
    assert wait == pytest.approx(1.0) and "'ada'" in why
    assert throttle.admit("ada", "10.0.0.2") == (0.0, "")  # ada, from her own address, still signs in
    clock.now += 1.0
    fail(throttle, "ada", "10.0.0.1", 1, clock)
    assert throttle.admit("ada", "10.0.0.1")[0] == pytest.approx(2.0)  # doubled
    clock.now += 2.0
    fail(throttle, "ada", "10.0.0.1", 1, clock)
    assert throttle.admit("ada", "10.0.0.1")[0] == pytest.approx(4.0)


def test_the_back_off_is_capped():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=10**6, clock=clock)
    for _ in range(40):
        clock.now += MAX_DELAY_S
        fail(throttle, "ada", "10.0.0.1", 1, clock)
    assert throttle.admit("ada", "10.0.0.1")[0] == pytest.approx(MAX_DELAY_S)


def test_failures_across_names_from_one_address_back_off_that_address():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=1000, clock=clock)
    for i in range(FREE_FAILURES_PER_ADDRESS):
        fail(throttle, f"name{i}", "10.0.0.1", 1, clock)
    wait, why = throttle.admit("someone-else", "10.0.0.1")
    assert wait > 0 and "from this address" in why
    assert throttle.admit("someone-else", "10.0.0.2") == (0.0, "")


def test_attempts_per_address_are_limited_across_names_in_a_sliding_minute():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=3, clock=clock)
    for i in range(3):
        assert throttle.admit(f"name{i}", "10.0.0.1") == (0.0, "")  # attempts, whatever their outcome
        clock.now += 10
    wait, why = throttle.admit("name9", "10.0.0.1")
    assert wait == pytest.approx(30.0) and "attempts" in why
    assert throttle.admit("name9", "10.0.0.2") == (0.0, "")
    clock.now += 30.0
    assert throttle.admit("name9", "10.0.0.1") == (0.0, "")


def test_a_success_clears_the_pair_but_not_the_address():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=1000, clock=clock)
    fail(throttle, "ada", "10.0.0.1", FREE_FAILURES_PER_NAME - 1, clock)
    throttle.succeeded("ada", "10.0.0.1")
    fail(throttle, "ada", "10.0.0.1", FREE_FAILURES_PER_NAME - 1, clock)
    assert throttle.admit("ada", "10.0.0.1") == (0.0, "")
    # Signing in as yourself between guesses does not reset the address's count.
    for i in range(FREE_FAILURES_PER_ADDRESS - 1):
        fail(throttle, f"bob{i}", "10.0.0.9", 1, clock)
    throttle.succeeded("eve", "10.0.0.9")
    fail(throttle, "carol", "10.0.0.9", 1, clock)
    assert throttle.admit("dave", "10.0.0.9")[0] > 0


def test_failures_are_forgotten_after_an_hour_of_quiet():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=1000, clock=clock)
    for _ in range(FREE_FAILURES_PER_NAME + 5):
        throttle.failed("ada", "10.0.0.1")
    assert throttle.admit("ada", "10.0.0.1")[0] > 0
    clock.now += 3600.0
    assert throttle.admit("ada", "10.0.0.1") == (0.0, "")
    fail(throttle, "ada", "10.0.0.1", 1, clock)
    assert throttle.admit("ada", "10.0.0.1") == (0.0, "")  # counting starts again


def test_attacker_chosen_names_and_addresses_cannot_grow_the_tables_without_bound():
    clock = Clock()
    throttle = SignInThrottle(attempts_per_min=10**9, clock=clock)
    for i in range(MAX_TRACKED_KEYS * 3):
        throttle.failed(f"name{i}", f"10.{i >> 16 & 255}.{i >> 8 & 255}.{i & 255}")
    assert len(throttle._by_name) <= MAX_TRACKED_KEYS
    assert len(throttle._by_address) <= MAX_TRACKED_KEYS


def test_the_hash_gate_refuses_at_once_beyond_its_bound_and_counts():
    gate = HashGate(2)
    entered, leave = threading.Barrier(3), threading.Event()

    def hold():
        with gate.slot():
            entered.wait()
            leave.wait()

    holders = [threading.Thread(target=hold) for _ in range(2)]
    for t in holders:
        t.start()
    entered.wait()
    with pytest.raises(HashingBusy):
        with gate.slot():
            pass
    leave.set()
    for t in holders:
        t.join()
    with gate.slot():
        pass
    assert (gate.peak, gate.hashed, gate.refused, gate.active) == (2, 3, 1, 0)
    assert gate.run(lambda x: threading.current_thread().name + x, "!").startswith("argon2")  # its own threads
    gate.close()
