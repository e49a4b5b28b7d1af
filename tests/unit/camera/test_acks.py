"""The ack accounting of an acknowledging MJPEG page (camera/acks.py), with an injected clock: bytes
written, acknowledged and outstanding; acknowledgements only move forward; anything but a whole
number up to what was written is refused and changes nothing; a page silent for ACK_STALL_S with
bytes outstanding is stalled; ids are not found by another identity."""

import pytest

from rover_web.camera.acks import ACK_STALL_S, AckedStream, AckedStreams
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
    assert stream.report() == {"acked_bytes": 15_000, "unacked_bytes": 5_009}
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
    stream = AckedStream(None, Clock())
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
