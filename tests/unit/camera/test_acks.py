"""The ack accounting of an acknowledging MJPEG page (camera/acks.py), with an injected clock: bytes
written, acknowledged and outstanding; acknowledgements only move forward; anything but a whole
number up to what was written is refused and changes nothing; a page silent for ACK_STALL_S with
bytes outstanding is stalled; ids are not found by another identity."""

import pytest

from rover_web.camera.acks import ACK_STALL_S, MIN_DELAY_WINDOW_S, RATE_WINDOW_S, AckedStream, AckedStreams
from rover_web.web.validate import InvalidInput


class Clock:
    def __init__(self):
        self.t = 500.0

    def __call__(self):
        return self.t


def test_written_acked_and_unacked():
    stream = AckedStream("alice", Clock())
    assert (stream.written, stream.acked, stream.unacked) == (0, 0, 0)
    stream.wrote(9)
    stream.wrote(20_000)
    assert (stream.written, stream.unacked) == (20_009, 20_009)
    assert stream.ack(15_000) is True
    assert (stream.acked, stream.unacked) == (15_000, 5_009)
    assert stream.report() == {"acked_bytes": 15_000, "unacked_bytes": 5_009, "in_flight_bytes": 0}
    assert stream.ack(20_009) is True and stream.unacked == 0


def test_acks_only_move_forward():
    stream = AckedStream(None, Clock())
    stream.wrote(1000)
    stream.ack(800)
    assert stream.ack(500) is False and stream.ack(800) is False
    assert stream.acked == 800


@pytest.mark.parametrize("value, code", [
    (1.5, "bad_type"), (100.0, "bad_type"), ("100", "bad_type"), (None, "bad_type"), (True, "bad_type"),
    (False, "bad_type"), ([100], "bad_type"), (float("nan"), "bad_type"),
    (-1, "out_of_range"), (1001, "out_of_range"), (10**400, "out_of_range"),
])
def test_a_bad_ack_is_refused_and_changes_nothing(value, code):
    clock = Clock()
    stream = AckedStream(None, clock)
    stream.wrote(1000)
    stream.ack(400)
    clock.t += ACK_STALL_S - 1
    with pytest.raises(InvalidInput) as refused:
        stream.ack(value)
    assert refused.value.code == code
    assert (stream.written, stream.acked) == (1000, 400)
    clock.t += 1
    assert stream.stalled()  # a refused ack is no sign of life either


def test_the_queue_is_the_socket_or_the_unacknowledged_bytes_whichever_is_more():
    stream = AckedStream(None, Clock())  # no ack measured yet: nothing is taken to be on its way
    stream.wrote(50_000)
    stream.ack(10_000)
    assert stream.queued(None) == 40_000  # a socket the kernel cannot tell about
    assert stream.queued(0) == 40_000  # a hop that acknowledged everything at once
    assert stream.queued(60_000) == 60_000


def test_a_page_silent_with_bytes_outstanding_is_stalled():
    clock = Clock()
    stream = AckedStream(None, clock)
    clock.t += 10 * ACK_STALL_S
    assert not stream.stalled()  # nothing outstanding: nothing to wait for
    stream.wrote(1000)  # the wait starts with the first byte outstanding
    clock.t += ACK_STALL_S - 0.1
    assert not stream.stalled()
    stream.ack(500)  # progress restarts the wait
    clock.t += ACK_STALL_S - 0.1
    assert not stream.stalled()
    stream.wrote(1000)  # more written while bytes are outstanding does not restart it
    clock.t += 0.1
    assert stream.stalled()
    stream.ack(2000)
    assert not stream.stalled()


def test_an_id_is_found_only_by_whoever_opened_it_and_only_while_open():
    registry = AckedStreams(Clock())
    alice = registry.open("alice")
    anonymous = registry.open(None)
    assert len(alice.id) >= 20 and alice.id != anonymous.id
    assert registry.find(alice.id, "alice") is alice
    assert registry.find(alice.id, "bob") is None
    assert registry.find(alice.id, None) is None
    assert registry.find(anonymous.id, None) is anonymous
    assert registry.find(anonymous.id, "alice") is None
    assert registry.find("no-such-id", "alice") is None
    registry.close(alice)
    assert registry.find(alice.id, "alice") is None and len(registry) == 1


class Path:
    """A page behind a path of `rate` bytes/s and `delay` s (write → ack), behind a hop that empties
    the server's socket at once: the server writes a frame whenever stream.queued(0) is at most
    `keep_queue` (the rate control's rule), and the page acknowledges all it has `delay` after the
    path has carried it."""

    def __init__(self, stream, clock, *, rate, delay, frame, keep_queue=2048):
        self.stream, self.clock = stream, clock
        self.rate, self.delay, self.frame, self.keep_queue = rate, delay, frame, keep_queue
        self.carried_until = clock.t  # when the path has carried everything written so far
        self.deliveries = []  # (ack time, written in all)

    def run(self, seconds, step=0.005):
        """Returns the most bytes that waited at the path's entrance, beyond the frame just written."""
        most_waiting, end = 0, self.clock.t + seconds
        while self.clock.t < end:
            while self.deliveries and self.deliveries[0][0] <= self.clock.t:
                self.stream.ack(self.deliveries.pop(0)[1])
            if self.stream.queued(0) <= self.keep_queue:
                self.stream.wrote(self.frame)
                self.carried_until = max(self.carried_until, self.clock.t) + self.frame / self.rate
                self.deliveries.append((self.carried_until + self.delay, self.stream.written))
            waiting = max(0.0, self.carried_until - self.clock.t) * self.rate
            most_waiting = max(most_waiting, int(waiting) - self.frame)
            self.clock.t += step
        return most_waiting


def test_bytes_on_their_way_are_not_a_queue_so_a_slow_round_trip_does_not_throttle_a_fast_path():
    clock = Clock()
    stream = AckedStream(None, clock)
    rate, delay, frame = 250_000, 0.12, 10_000  # wifi-edge: 2 Mbit/s, 120 ms round trip
    path = Path(stream, clock, rate=rate, delay=delay, frame=frame)
    path.run(3)
    acked0, t0 = stream.acked, clock.t
    most_waiting = path.run(5)
    delivered = (stream.acked - acked0) / (clock.t - t0)
    # Stop-and-wait would carry one frame per round trip (about 64 kB/s here); counting a round
    # trip's worth as on its way lets the page get most of the link ...
    assert delivered > 0.7 * rate
    # ... and nothing piles up at the link's entrance beyond about a frame.
    assert most_waiting <= 2 * frame
    # A round trip's worth at the path's rate (the round trip of a write includes carrying it).
    assert 0.5 * rate * delay < stream.in_flight() <= 1.1 * (rate * delay + frame)


def test_what_is_on_its_way_falls_to_nothing_when_the_page_falls_silent():
    clock = Clock()
    stream = AckedStream(None, clock)
    Path(stream, clock, rate=250_000, delay=0.12, frame=10_000).run(3)
    assert stream.in_flight() > 0
    clock.t += RATE_WINDOW_S + 0.01  # no acks for a second: no rate, nothing counted as on its way
    assert stream.in_flight() == 0
    assert stream.queued(0) == stream.unacked


def test_the_round_trip_is_the_least_delay_of_the_window():
    clock = Clock()
    stream = AckedStream(None, clock)
    stream.wrote(1000)
    clock.t += 0.1
    stream.ack(1000)  # 100 ms
    stream.wrote(1000)
    clock.t += 0.5
    stream.ack(2000)  # 500 ms (a queue): the 100 ms still stands
    assert stream.in_flight() == int(2000 / RATE_WINDOW_S * 0.1)
    clock.t += MIN_DELAY_WINDOW_S - 0.55
    stream.wrote(1000)
    clock.t += 0.3
    stream.ack(3000)  # the 100 ms sample has left the window; 300 ms is the least since
    assert stream.in_flight() == int(1000 / RATE_WINDOW_S * 0.3)
