"""bench/link.py's figures from what the robot's side saw: the stick's values, and /cmd_vel's Twists.

Twists are (monotonic arrival, linear.x, angular.z) from bench/cmd_vel_subscriber.py; outages are
the emulator's (start, end) windows on the same clock.
"""

from __future__ import annotations

import bisect

VALUES = 500  # distinct stick values, then they repeat (20 s at 25 Hz)
MAX_LINEAR = 5.0  # ROVER_WEB_MAX_LINEAR_MPS's default: the Twist is the stick's fraction of it
OUTAGE_GRACE_S = 1.0  # stops up to this long after an outage are the outage's


def stick_value(i: int) -> float:
    return round(0.3 + (i % VALUES + 1) / 2000, 6)


def value_index(linear: float) -> int | None:
    k = round((linear / MAX_LINEAR - 0.3) * 2000) - 1
    return k if 0 <= k < VALUES else None


def teleop_latencies(sent: list[tuple[float, int]], twists: list[tuple[float, float, float]]) -> list[float]:
    """Each frame's latency: its send → the first Twist with its value before that value is sent again."""
    arrivals: dict[int, list[float]] = {}
    for t, lin, _ in twists:
        if (k := value_index(lin)) is not None:
            arrivals.setdefault(k, []).append(t)
    out = []
    next_send: dict[int, float] = {}
    for t_sent, k in reversed(sent):
        times = arrivals.get(k, [])
        j = bisect.bisect_left(times, t_sent)
        if j < len(times) and times[j] < next_send.get(k, float("inf")):
            out.append(times[j] - t_sent)
        next_send[k] = t_sent
    return out


def spurious_stops(twists, start: float, end: float, outages: list[tuple[float, float]]) -> tuple[int, int]:
    """(stops outside outages, stops inside them): zero Twists after a non-zero one within [start, end]."""
    outside = inside = 0
    moving = False
    for t, lin, ang in twists:
        zero = lin == 0.0 and ang == 0.0
        if zero and moving and start <= t <= end:
            if any(a <= t <= b + OUTAGE_GRACE_S for a, b in outages):
                inside += 1
            else:
                outside += 1
        moving = not zero
    return outside, inside


def outage_zeros(twists, start: float, end: float,
                 outages: list[tuple[float, float]]) -> tuple[list[float | None], list[int]]:
    """For each outage that began while the stick was held: (ms from its start to the first zero
    Twist, None if none came; non-zero Twists after that zero and before the outage ended).

    The deadman bound is counted from the last input's freshness, which is no later than the
    outage's start (nothing the operator sends arrives during it), so the outage's start is the
    latest the bound's clock can have started: a zero later than the bound after it is a breach.
    A robot already at zero when the outage began (a stall just before) counts as 0 ms. The
    Twists should reach past `end` by the bound and more, or an outage near the end reads as
    None."""
    zeros: list[float | None] = []
    moves: list[int] = []
    for a, b in outages:
        if not start <= a <= end:
            continue
        before = [tw for tw in twists if tw[0] < a]
        if before and before[-1][1] == 0.0 and before[-1][2] == 0.0:
            t_zero = a
        else:
            t_zero = next((t for t, lin, ang in twists if t >= a and lin == 0.0 and ang == 0.0), None)
        zeros.append(None if t_zero is None else round((t_zero - a) * 1000, 1))
        moves.append(0 if t_zero is None else
                     sum(1 for t, lin, ang in twists if t_zero < t <= b and (lin != 0.0 or ang != 0.0)))
    return zeros, moves


def down_since(t: float, windows: list[tuple[float, float, str]]) -> float:
    """When the link went down for good before t: a stall that ran into the outage (back to back
    or overlapping) already kept the operator's frames from arriving, so the deadman's clock may
    have started there, before the outage did."""
    begin, changed = t, True
    while changed:
        changed = False
        for a, b, _ in windows:
            if a < begin <= b:
                begin, changed = a, True
    return begin


def deadman_bound_s(env: dict, settings) -> float:
    """The app's hard bound as this run's environment sets it (a bound below the hold is the hold)."""
    def value(name: str) -> float:
        default = next(s.default for s in settings if s.name == name)
        return float(env.get(f"ROVER_WEB_{name}", default))
    return max(value("TELEOP_DEADMAN_S"), value("TELEOP_DEADMAN_MAX_S"))


def first_outage_in(link, emulator_start: float, start: float, end: float) -> float | None:
    """When the profile's first scheduled outage falls in [start, end] (the schedule's first is at
    half the period after the emulator started, then one each period), or None."""
    if not (link.outage_every_s and link.outage_s):
        return None
    t = emulator_start + link.outage_every_s / 2
    while t < start:
        t += link.outage_every_s
    return t if t <= end else None
