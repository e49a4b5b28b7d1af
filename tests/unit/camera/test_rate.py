"""Per-viewer rate control against a simulated path (fake clock): a slow link lowers frame rate, then
quality, then size; recovery climbs back with hysteresis; the socket never holds more than one frame
beyond the budget; the per-viewer cap and the total budget hold."""

import math

import pytest

from rover_web.camera.rate import (
    FPS_FLOOR,
    QUEUE_BUDGET_BYTES,
    UP_HOLD_S,
    Budget,
    Meter,
    Step,
    ViewerRate,
    fair_shares,
    ladder,
    model_size,
)

TOP_BYTES = 60_000  # a 640×480 quality-80 frame with grain


class Clock:
    def __init__(self):
        self.t = 1000.0

    def __call__(self):
        return self.t


class Link:
    """A path that drains the socket at `bps` (bytes/s); `queued` is what SIOCOUTQ would say."""

    def __init__(self, clock, bps):
        self.clock, self.bps = clock, bps
        self.queue = 0.0
        self.at = clock()
        self.delivered = []  # (time, bytes) as the path carries them

    def queued(self):
        now = self.clock()
        gone = min(self.queue, self.bps * (now - self.at))
        if gone:
            self.delivered.append((now, gone))
        self.queue -= gone
        self.at = now
        return int(math.ceil(self.queue))

    def write(self, nbytes):
        self.queued()
        self.queue += nbytes


def frame_size(rate, index):
    return int(TOP_BYTES * model_size(rate.steps[index]) / model_size(rate.steps[0]))


class Viewer:
    """The stream loop of rover_web/camera/routes.py, in simulated time, with a 30 Hz camera:
    wait for the pacing, take the newest frame, wait for the socket to let the last one go, write."""

    def __init__(self, clock, link, rate, camera_hz=30.0):
        self.clock, self.link, self.rate = clock, link, rate
        self.camera_hz = camera_hz
        rate.source_fps = camera_hz
        self.sent = []  # (time, bytes, step index, queued before)
        self.last_frame = -1

    def run_until(self, end):
        while self.clock.t < end:
            pause = self.rate.pace_s(self.link.queued)
            if pause > 0:
                self.clock.t += min(pause, 0.05)
                continue
            frame = math.floor(self.clock.t * self.camera_hz)
            if frame <= self.last_frame:  # the newest frame was sent already: wait for the next one
                self.clock.t = (self.last_frame + 1) / self.camera_hz + 1e-9
                continue
            hold = self.rate.hold_s(self.link.queued())
            if hold > 0:
                self.clock.t += hold
                continue
            self.last_frame = math.floor(self.clock.t * self.camera_hz)  # the newest, after any hold
            index = self.rate.index
            nbytes = frame_size(self.rate, index)
            before = self.link.queued()
            self.sent.append((self.clock.t, nbytes, index, before))
            self.link.write(nbytes)
            self.rate.sent(nbytes, self.clock.t, before, step_index=index)

    def fps(self, start, end):
        return sum(1 for t, *_ in self.sent if start <= t < end) / (end - start)

    def bps(self, start, end):
        return sum(n for t, n, *_ in self.sent if start <= t < end) / (end - start)

    def steps(self, start=0.0, end=math.inf):
        return [i for t, _, i, _ in self.sent if start <= t < end]


def make(bps, quality=80, clock=None, **kwargs):
    clock = clock or Clock()
    link = Link(clock, bps)
    rate = ViewerRate(quality, clock=clock, **kwargs)
    return clock, link, rate, Viewer(clock, link, rate)


def visited(steps):
    """The distinct steps in the order first used."""
    out = []
    for s in steps:
        if not out or out[-1] != s:
            out.append(s)
    return out


def test_ladder_lowers_quality_before_size():
    assert ladder(80) == (Step(80), Step(60), Step(40), Step(25), Step(25, 0.75), Step(25, 0.5), Step(25, 0.25))
    assert ladder(50)[:3] == (Step(50), Step(40), Step(25))
    assert ladder(20) == (Step(20), Step(20, 0.75), Step(20, 0.5), Step(20, 0.25))


def test_a_fast_path_keeps_full_rate_and_quality():
    clock, link, rate, viewer = make(50e6)
    viewer.run_until(clock.t + 10)
    assert set(viewer.steps()) == {0}
    assert viewer.fps(clock.t - 5, clock.t) > 29


def test_a_slow_link_lowers_frame_rate_first_then_quality_then_size():
    # 1.2 MB/s carries 20 fps at quality 80: frame rate alone is lowered.
    clock, link, rate, viewer = make(1_200_000)
    viewer.run_until(clock.t + 20)
    assert set(viewer.steps(clock.t - 10)) == {0}
    assert FPS_FLOOR <= viewer.fps(clock.t - 10, clock.t) < 22
    # 300 kB/s: 5 fps at quality 80; quality goes down, the size stays.
    clock, link, rate, viewer = make(300_000)
    viewer.run_until(clock.t + 30)
    path = visited(viewer.steps())
    assert path == sorted(path) and rate.step.scale == 1.0 and rate.step.quality < 80
    assert viewer.fps(clock.t - 10, clock.t) >= FPS_FLOOR * 0.8
    # 15 kB/s: quality is at its lowest, then the size goes down, in that order.
    clock, link, rate, viewer = make(15_000)
    viewer.run_until(clock.t + 60)
    path = visited(viewer.steps())
    assert path == sorted(path)
    assert rate.step.quality == 25 and rate.step.scale < 1.0
    for index in path:
        if rate.steps[index].scale < 1.0:
            assert rate.steps[index].quality == 25  # size only once quality is at its lowest


def test_the_socket_never_holds_a_frame_beyond_the_budget_when_the_next_is_written():
    for bps in (5_000, 50_000, 500_000):
        clock, link, rate, viewer = make(bps)
        viewer.run_until(clock.t + 30)
        assert max(before for *_, before in viewer.sent) <= QUEUE_BUDGET_BYTES
        biggest = max(n for _, n, *_ in viewer.sent)
        assert max(before for *_, before in viewer.sent) <= max(2048, biggest / 4)
        # and what was written is what the link could carry (nothing piles up)
        assert viewer.bps(clock.t - 20, clock.t) <= bps * 1.1


def test_recovery_steps_up_one_at_a_time_with_hysteresis():
    clock, link, rate, viewer = make(15_000)
    viewer.run_until(clock.t + 60)
    low = rate.index
    assert low >= 4
    link.queued()
    link.bps = 50e6  # the link recovers
    recovered_at = clock.t
    viewer.run_until(clock.t + 60)
    changes = [(t, i) for (t, _, i, _), (_, _, j, _) in zip(viewer.sent[1:], viewer.sent, strict=False)
               if i != j and t > recovered_at]
    assert rate.index == 0
    assert all(b[1] == a[1] - 1 for a, b in zip([(recovered_at, low)] + changes, changes, strict=False))
    times = [recovered_at] + [t for t, _ in changes]
    assert all(b - a >= UP_HOLD_S - 0.1 for a, b in zip(times, times[1:], strict=False))
    assert viewer.fps(clock.t - 5, clock.t) > 29


def test_a_link_at_a_step_boundary_does_not_flap():
    # About the rate where quality 60 runs at the floor: the step may settle, not oscillate.
    bps = FPS_FLOOR * TOP_BYTES * 0.5 * 1.1
    clock, link, rate, viewer = make(bps)
    viewer.run_until(clock.t + 20)
    start = clock.t
    viewer.run_until(clock.t + 60)
    assert len(visited(viewer.steps(start))) <= 5  # at most a couple of changes a minute


def test_a_brief_stall_costs_a_moment_not_the_quality():
    clock, link, rate, viewer = make(1_000_000)
    viewer.run_until(clock.t + 10)
    assert rate.index == 0
    link.queued()
    link.bps = 0.001  # a TCP retransmission stall: nothing moves for 0.4 s
    viewer.run_until(clock.t + 0.4)
    link.queued()
    link.bps = 1_000_000
    viewer.run_until(clock.t + 10)
    assert rate.index == 0 or max(viewer.steps(clock.t - 10)) <= 1
    assert viewer.fps(clock.t - 5, clock.t) > 10


def test_the_per_viewer_cap_holds_on_a_fast_link():
    clock, link, rate, viewer = make(50e6, max_bps=200_000)
    viewer.run_until(clock.t + 30)
    assert viewer.bps(clock.t - 20, clock.t) <= 200_000 * 1.05
    assert viewer.fps(clock.t - 20, clock.t) >= FPS_FLOOR * 0.8  # quality went down to keep a usable rate


def test_the_total_budget_is_shared_and_a_slow_viewer_leaves_its_part_to_the_others():
    budget = Budget(300_000)
    a = make(50e6, budget=budget)[3]
    b = make(50e6, budget=budget)[3]

    def run(viewers, seconds):
        for _ in range(int(seconds * 10)):  # in 0.1 s turns, each viewer on its own clock
            for viewer in viewers:
                viewer.run_until(viewer.clock.t + 0.1)

    def bps(viewer):
        return viewer.bps(viewer.clock.t - 15, viewer.clock.t)

    run((a, b), 30)
    assert bps(a) + bps(b) <= 300_000 * 1.1
    assert bps(a) == pytest.approx(bps(b), rel=0.35)
    # a third viewer on a 40 kB/s path takes only what its path carries
    c = make(40_000, budget=budget)[3]
    run((a, b, c), 40)
    assert bps(c) <= 40_000 * 1.1
    assert bps(a) + bps(b) + bps(c) <= 300_000 * 1.1
    assert bps(a) > 100_000 and bps(b) > 100_000  # more than a third each
    c.rate.close()
    assert len(budget._demands) == 2


def test_fair_shares():
    assert fair_shares({1: 10, 2: 100, 3: 100}, 90) == {1: 10, 2: 40, 3: 40}
    assert fair_shares({1: 10, 2: 20}, 90) == {1: 10, 2: 20}
    assert fair_shares({1: math.inf, 2: math.inf}, 90) == {1: 45, 2: 45}
    assert Budget(None).share(Budget(None).join(), 5.0) == math.inf


def test_meter_reports_fps_size_and_kbps_over_its_window():
    clock = Clock()
    meter = Meter(clock)
    for _ in range(40):
        meter.sent(10_000, (320, 240), 60)
        clock.t += 0.1
    report = meter.report()
    assert report["fps"] == pytest.approx(10, rel=0.1) and report["kbps"] == pytest.approx(800, rel=0.1)
    assert (report["width"], report["height"], report["quality"]) == (320, 240, 60)
    clock.t += 10
    assert meter.report()["fps"] == 0 and meter.report()["frames"] == 40


def test_a_refused_step_is_not_taken():
    clock, link, rate, viewer = make(120_000)
    rate.refused(1)
    rate.refused(2)
    viewer.run_until(clock.t + 30)
    assert 1 not in viewer.steps() and 2 not in viewer.steps()


def test_a_fast_path_whose_reader_is_sometimes_busy_keeps_full_rate_and_quality():
    # A loaded machine: the reader stops for 60 ms every half second. That is not a slow link.
    clock, link, rate, viewer = make(50e6)
    for _ in range(60):
        viewer.run_until(clock.t + 0.44)
        link.queued()
        link.bps = 0.001
        viewer.run_until(clock.t + 0.06)
        link.queued()
        link.bps = 50e6
    assert set(viewer.steps(clock.t - 20)) == {0}
    assert viewer.fps(clock.t - 20, clock.t) > 25


def test_the_report_can_be_read_while_the_stream_adds_samples():
    # GET /api/camera/viewers reads path_bps() on a request thread while the stream's thread adds
    # drain samples: a generator over the deque let that thread in mid-iteration (CI: "deque mutated
    # during iteration", a 500). With a tiny switch interval the race shows within a few thousand reads.
    import sys
    import threading

    from rover_web.camera.rate import ViewerRate

    rate = ViewerRate(80)
    stop = threading.Event()

    def add():
        n = 0
        while not stop.is_set():
            n += 1
            rate._samples.append((n, float(n)))

    writer = threading.Thread(target=add)
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    writer.start()
    try:
        for _ in range(20_000):
            rate.path_bps()
    finally:
        stop.set()
        writer.join()
        sys.setswitchinterval(interval)
