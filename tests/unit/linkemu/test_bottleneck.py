"""The link's scheduling maths on a hand-driven clock: rate, buffer, delay, order, stalls, outages, loss."""

import random

import pytest

from rover_web.linkemu.bottleneck import OUTAGE, RTO_MIN_S, STALL, Bottleneck, Flow, Schedule
from rover_web.linkemu.profiles import profile


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def link(clock, seed=1, **settings):
    p = profile("custom", **settings)
    schedule = Schedule(p, random.Random(seed), clock.t)
    return Bottleneck(p, schedule, random.Random(seed + 1), clock=clock)


def arrivals(b, clock, until, step=0.001):
    """(time, flow, data) of everything due, stepping the clock to `until`."""
    out = []
    while clock.t <= until + 1e-9:
        out += [(clock.t, flow, data) for flow, data in b.due()]
        clock.t = round(clock.t + step, 9)
    return out


def test_bytes_leave_at_the_rate_then_travel_the_delay():
    clock = Clock()
    b = link(clock, rate_kbps=80, delay_ms=50, buffer_kb=100)  # 10,000 bytes/s
    flow = Flow()
    for _ in range(5):
        assert b.push(flow, b"x" * 1000)  # 0.1 s each on the wire
    got = arrivals(b, clock, 1.0)
    assert [t for t, _, _ in got] == pytest.approx([0.15, 0.25, 0.35, 0.45, 0.55], abs=0.0015)
    assert b.bytes_passed == 5000 and b.queued_bytes == 0


def test_a_full_buffer_delays_newcomers_by_its_depth_bufferbloat():
    clock = Clock()
    b = link(clock, rate_kbps=80, delay_ms=0, buffer_kb=10)  # 10 kB buffer = 1 s at 10 kB/s
    bulk, frame = Flow(), Flow()
    while b.room() >= 1000:
        b.push(bulk, b"v" * 1000)
    assert b.room() == 0 and b.queued_bytes == 10_000
    with pytest.raises(OverflowError):
        b.push(frame, b"f")  # a TCP relay must wait for room: backpressure, never loss
    clock.t = 0.1  # one chunk left: room for one more
    assert len(b.due()) == 1 and b.room() == 1000
    b.push(frame, b"f" * 10)
    got = arrivals(b, clock, 2.0)
    frame_at = next(t for t, flow, _ in got if flow is frame)
    assert frame_at == pytest.approx(1.001, abs=0.002)  # queued behind 0.9 s of video


def test_jitter_stays_in_its_range_and_a_flow_keeps_its_order():
    clock = Clock()
    b = link(clock, seed=7, rate_kbps=1_000_000, delay_ms=60, jitter_ms=40, buffer_kb=1000)
    flows = [Flow(), Flow()]
    sent, got = {}, []
    for i in range(400):
        clock.t = round(i * 0.002, 9)
        data = i.to_bytes(2, "big")
        sent[data] = clock.t
        b.push(flows[i % 2], data)
        got += [(clock.t, f, d) for f, d in b.due()]
    got += arrivals(b, clock, 2.0)
    assert len(got) == 400
    delays = [t - sent[d] for t, _, d in got]
    assert min(delays) >= 0.020 - 0.002 and max(delays) <= 0.100 + 0.002
    assert max(delays) - min(delays) > 0.030  # it does jitter
    for flow in flows:
        order = [int.from_bytes(d, "big") for _, f, d in got if f is flow]
        assert order == sorted(order)


def test_a_stall_holds_every_byte_then_they_flow_in_order():
    clock = Clock()
    b = link(clock, rate_kbps=1_000_000, delay_ms=10, buffer_kb=100)
    flow = Flow()
    b.schedule.add(STALL, 0.0, 0.4)
    for i in range(3):
        clock.t = i * 0.1
        b.push(flow, bytes([i]))
    got = arrivals(b, clock, 1.0)
    assert [d for _, _, d in got] == [b"\x00", b"\x01", b"\x02"]
    assert all(0.4 <= t <= 0.42 for t, _, _ in got)
    assert b.schedule.count(STALL, clock.t) == 1


def test_an_outage_holds_tcp_bytes_and_drops_datagrams():
    clock = Clock()
    b = link(clock, rate_kbps=1_000_000, delay_ms=20, buffer_kb=100)
    tcp, udp = Flow(), Flow(datagrams=True)
    b.push(tcp, b"early")  # in flight when the outage starts
    b.push(udp, b"early")
    clock.t = 0.01
    b.schedule.add(OUTAGE, 0.01, 1.0)
    assert b.push(tcp, b"during")
    assert not b.push(udp, b"during")
    got = arrivals(b, clock, 2.0)
    assert [(f is tcp, d) for _, f, d in got] == [(True, b"early"), (True, b"during")]
    assert all(t >= 1.01 for t, _, _ in got)
    assert b.packets_dropped == 2 and b.bytes_dropped == len(b"early") + len(b"during")


def test_datagrams_are_dropped_at_the_tail_when_the_buffer_is_full():
    clock = Clock()
    b = link(clock, rate_kbps=8, delay_ms=0, buffer_kb=1)  # 1 kB/s, a 1000-byte buffer
    flow = Flow(datagrams=True)
    results = [b.push(flow, b"d" * 200) for _ in range(8)]
    assert results == [True] * 5 + [False] * 3
    assert b.packets_dropped == 3 and b.queue_peak == 1000


def test_datagram_loss_matches_the_profile_over_many_packets():
    clock = Clock()
    b = link(clock, seed=3, rate_kbps=1_000_000, delay_ms=0, buffer_kb=10_000, loss=0.1)
    flow = Flow(datagrams=True)
    kept = sum(b.push(flow, b"p" * 100) for _ in range(10_000))
    assert 8_700 <= kept <= 9_300
    assert b.packets_dropped == 10_000 - kept


def test_tcp_loss_becomes_retransmission_delay_not_loss():
    clock = Clock()
    b = link(clock, seed=5, rate_kbps=1_000_000, delay_ms=30, buffer_kb=10_000, loss=0.02)
    flow = Flow()
    got = []
    for i in range(2000):
        clock.t = i * 0.001
        b.push(flow, b"s" * 1448)
        got += b.due()
    clock.t = 10.0
    got += b.due()
    assert len(got) == 2000 and b.packets_dropped == 0
    # About 2 % of segments waited a retransmission timeout: the stream's last byte with them.
    assert flow.last_arrival >= 1.999 + 0.030 + RTO_MIN_S


def test_stalls_come_about_as_often_as_the_profile_says_and_outages_on_the_period():
    p = profile("custom", stall_every_s=10, stall_ms=400, outage_every_s=60, outage_s=3)
    schedule = Schedule(p, random.Random(11), 0.0)
    down_time = {STALL: 0.0, OUTAGE: 0.0}
    t = 0.0
    while t < 1200:
        if (down := schedule.down(t)) is not None:
            down_time[down[1]] += 0.01
        t += 0.01
    schedule.prune(1200)
    assert 90 <= schedule.count(STALL, 1200) <= 150
    assert schedule.count(OUTAGE, 1200) == 20  # at 30, 90, ..., 1170 s
    assert down_time[OUTAGE] == pytest.approx(60, rel=0.05)
    assert Schedule(p, random.Random(11), 0.0).down(30.5) == (33.0, OUTAGE)
    outages = [(w.start, w.end) for w in schedule.begun(1200) if w.kind == OUTAGE]
    assert outages[:2] == [(30, 33), (90, 93)] and len(outages) == 20


def test_the_same_seed_gives_the_same_stalls():
    p = profile("wifi-edge")
    a, b = Schedule(p, random.Random(4), 0.0), Schedule(p, random.Random(4), 0.0)
    assert [a.down(t / 10) for t in range(3000)] == [b.down(t / 10) for t in range(3000)]


def test_next_wakeup_says_when_to_look_again():
    clock = Clock()
    b = link(clock, rate_kbps=80, delay_ms=100, buffer_kb=10)
    assert b.next_wakeup() is None
    b.push(Flow(), b"x" * 1000)
    assert b.next_wakeup() == pytest.approx(0.1)  # leaves the buffer
    clock.t = 0.1
    assert b.next_wakeup() == pytest.approx(0.2)  # arrives
    b.schedule.add(STALL, 0.15, 0.5)
    clock.t = 0.2
    assert b.due() == [] and b.next_wakeup() == pytest.approx(0.65)
