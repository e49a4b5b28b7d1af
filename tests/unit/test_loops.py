"""core.loops: periodic work that stops with the app, and gated loops that sleep while idle."""

import threading
import time

import pytest

from rover_web.core.loops import GATE_CHECK_S, every


def test_a_loop_runs_at_its_period_and_survives_an_exception():
    stopping = threading.Event()
    calls = []

    def work():
        calls.append(time.monotonic())
        if len(calls) == 2:
            raise RuntimeError("a bug in one call")

    loop = every(0.02, work, name="t", stopping=stopping)
    time.sleep(0.25)
    stopping.set()
    assert loop.join(1.0)
    assert len(calls) >= 5  # went on after the exception


def test_a_gated_loop_runs_only_while_its_gate_is_open():
    stopping, gate = threading.Event(), threading.Event()
    calls = []
    loop = every(0.01, lambda: calls.append(1), name="gated", stopping=stopping, only_while=gate)
    time.sleep(0.15)
    assert calls == []
    gate.set()
    deadline = time.monotonic() + 10  # a loaded machine runs a 10 ms loop late, not never
    while len(calls) < 5 and time.monotonic() < deadline:
        time.sleep(0.01)
    assert len(calls) >= 5
    gate.clear()
    time.sleep(0.05)
    n = len(calls)
    time.sleep(0.15)
    assert len(calls) <= n + 1  # at most one call that was already due
    stopping.set()
    assert loop.join(2.0)


def test_a_period_must_be_positive():
    with pytest.raises(ValueError):
        every(0, lambda: None, name="bad", stopping=threading.Event())


def test_a_loop_asleep_on_its_closed_gate_ends_when_joined_without_waiting_for_its_gate_check():
    stopping, gate = threading.Event(), threading.Event()
    calls = []
    loop = every(0.01, lambda: calls.append(1), name="gated", stopping=stopping, only_while=gate)
    time.sleep(0.05)  # asleep on the gate
    stopping.set()
    # Well inside GATE_CHECK_S (1 s): the join itself wakes it (every app's shutdown waited 1 s).
    assert loop.join(GATE_CHECK_S / 4)
    assert calls == []  # woken to end, not to work
