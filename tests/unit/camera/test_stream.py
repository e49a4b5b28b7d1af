"""One producer per stream: each frame encoded once for any number of viewers, slow viewers skip,
resources live exactly while used (plus a linger), stream arguments are checked."""

import threading
import time

import pytest

from rover_web.camera.imaging import Jpeg
from rover_web.camera.mjpeg import multipart_part
from rover_web.camera.params import parse_stream_args
from rover_web.camera.stream import FrameProducer, StreamClosed, StreamKey
from rover_web.core.leases import Closed, Full, Leases
from rover_web.web.validate import InvalidInput

KEY = StreamKey("/cam", "sensor_msgs/msg/Image", "default", None, None, 80)


class CountingEncoder:
    def __init__(self, delay_s=0.0):
        self.calls = []
        self.delay_s = delay_s
        self.lock = threading.Lock()

    def __call__(self, raw):
        with self.lock:
            self.calls.append(raw)
        time.sleep(self.delay_s)
        return Jpeg(f"jpeg of {raw}".encode(), 4, 3, stamp=float(raw))


def test_each_frame_is_encoded_once_for_many_viewers():
    encoder = CountingEncoder(delay_s=0.002)
    producer = FrameProducer(KEY, encoder)
    received = {i: [] for i in range(8)}
    stop = threading.Event()

    def viewer(i):
        seq = 0
        while not stop.is_set():
            got = producer.next_frame(seq, 0.2)
            if got:
                seq, jpeg = got
                received[i].append(jpeg.stamp)

    threads = [threading.Thread(target=viewer, args=(i,)) for i in range(8)]
    for t in threads:
        t.start()
    for n in range(1, 101):
        producer.put(n)
        time.sleep(0.005)
    time.sleep(0.1)
    stop.set()
    for t in threads:
        t.join(2)
    assert len(encoder.calls) == len(set(encoder.calls)) == producer.encodes  # never the same frame twice
    assert producer.encodes <= 100
    delivered = set().union(*map(set, received.values()))
    assert delivered == set(encoder.calls)  # nothing encoded that nobody got
    assert sum(len(v) for v in received.values()) >= 4 * producer.encodes  # frames are shared
    for stamps in received.values():
        assert stamps == sorted(set(stamps)) and stamps[-1] == 100  # in order, no repeats, ends current


def test_a_slow_viewer_skips_to_the_newest_frame():
    encoder = CountingEncoder()
    producer = FrameProducer(KEY, encoder)
    for n in range(1, 6):
        producer.put(n)
    seq, jpeg = producer.next_frame(0, 1.0)
    assert jpeg.stamp == 5.0 and seq == 5 and encoder.calls == [5]  # frames 1-4 were never encoded
    assert producer.next_frame(seq, 0.05) is None  # nothing newer: wait, then time out
    producer.put(6)
    producer.put(7)
    assert producer.next_frame(seq, 1.0)[1].stamp == 7.0


def test_a_viewer_that_already_has_the_frame_gets_it_without_encoding_again():
    encoder = CountingEncoder()
    producer = FrameProducer(KEY, encoder)
    producer.put(1)
    first = producer.next_frame(0, 1.0)
    assert producer.next_frame(0, 1.0) == first  # a second viewer joining now
    assert len(encoder.calls) == 1 and producer.latest() == first


def test_close_wakes_waiting_viewers():
    producer = FrameProducer(KEY, CountingEncoder())
    outcome = []

    def viewer():
        try:
            producer.next_frame(0, 10.0)
        except StreamClosed:
            outcome.append("closed")

    thread = threading.Thread(target=viewer)
    thread.start()
    time.sleep(0.05)
    producer.close()
    thread.join(2)
    assert outcome == ["closed"]


def test_stats_count_encodes_errors_and_times():
    producer = FrameProducer(KEY, lambda raw: Jpeg(b"x", 1, 1, error="bad", error_code="bad_image", encode_s=0.004))
    producer.put(1)
    producer.next_frame(0, 1.0)
    stats = producer.stats()
    assert stats["received"] == 1 and stats["encodes"] == 1 and stats["errors"] == 1
    assert stats["last_error"] == "bad" and stats["encode_ms"]["median"] == 4.0


def test_multipart_part_has_length_and_ends_with_the_boundary():
    part = multipart_part(Jpeg(b"\xff\xd8abc", 1, 1, stamp=12.5))
    assert part.startswith(b"Content-Type: image/jpeg\r\nContent-Length: 5\r\n")
    assert b"X-Timestamp: 12.500000000" in part and part.endswith(b"\xff\xd8abc\r\n--frame\r\n")


# --- leases ---

class FakeClock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def make_leases(linger_s=2.0, max_keys=None):
    opened, closed = [], []
    clock = FakeClock()

    def open_(key):
        opened.append(key)
        return f"sub:{key}:{len(opened)}"

    leases = Leases(open_, closed.append, linger_s, clock=clock, max_keys=max_keys)
    return leases, opened, closed, clock


def test_first_user_opens_the_rest_share():
    leases, opened, closed, _ = make_leases()
    assert leases.acquire("a") == leases.acquire("a") == "sub:a:1"
    assert opened == ["a"] and leases.users("a") == 2


def test_closed_only_after_the_last_user_has_been_gone_for_the_linger():
    leases, opened, closed, clock = make_leases(linger_s=2.0)
    leases.acquire("a")
    leases.acquire("a")
    leases.release("a")
    clock.now += 10
    assert leases.reap() == [] and closed == []  # one user still there
    leases.release("a")
    clock.now += 1.9
    assert leases.reap() == []
    clock.now += 0.2
    assert leases.reap() == ["a"] and closed == ["sub:a:1"] and "a" not in leases


def test_coming_back_within_the_linger_reuses_the_resource():
    leases, opened, closed, clock = make_leases(linger_s=2.0)
    leases.acquire("a")
    leases.release("a")
    clock.now += 1.0
    assert leases.acquire("a") == "sub:a:1"
    clock.now += 5.0
    assert leases.reap() == [] and opened == ["a"]


def test_an_open_that_fails_leaves_nothing_behind():
    def open_(key):
        raise RuntimeError("no such topic")

    leases = Leases(open_, lambda v: None, 1.0)
    with pytest.raises(RuntimeError):
        leases.acquire("a")
    assert len(leases) == 0


def test_at_the_cap_a_new_key_is_refused_while_every_resource_is_in_use():
    leases, opened, closed, _ = make_leases(max_keys=2)
    leases.acquire("a")
    leases.acquire("b")
    with pytest.raises(Full):
        leases.acquire("c")
    assert opened == ["a", "b"] and len(leases) == 2 and closed == []
    assert leases.acquire("a") == "sub:a:1"  # sharing an open one costs nothing and is never refused


def test_at_the_cap_the_longest_idle_resource_makes_room_at_once():
    leases, opened, closed, clock = make_leases(linger_s=60.0, max_keys=2)
    leases.acquire("a")
    leases.acquire("b")
    leases.release("b")
    clock.now += 1
    leases.release("a")
    assert leases.acquire("c") == "sub:c:3"
    assert closed == ["sub:b:2"] and "a" in leases and "b" not in leases


def test_an_evicted_resource_is_closed_even_when_the_new_one_fails_to_open():
    closed = []

    def open_(key):
        if key == "bad":
            raise RuntimeError("no such topic")
        return key

    leases = Leases(open_, closed.append, 60.0, max_keys=1)
    leases.acquire("a")
    leases.release("a")
    with pytest.raises(RuntimeError):
        leases.acquire("bad")
    assert closed == ["a"] and len(leases) == 0


def test_reaper_thread_closes_on_time_and_close_all_stops_everything():
    closed = []
    leases = Leases(lambda key: key, closed.append, linger_s=0.05)
    leases.start_reaper()
    leases.acquire("a")
    leases.acquire("b")
    leases.release("a")
    deadline = time.monotonic() + 2
    while closed != ["a"]:
        assert time.monotonic() < deadline, closed
        time.sleep(0.01)
    leases.close_all()
    assert closed == ["a", "b"]
    with pytest.raises(Closed):
        leases.acquire("c")


# --- query arguments ---

def parse(**args):
    return parse_stream_args(args, max_dimension=4096, default_quality=80)


def test_stream_arguments_defaults_and_web_video_server_compatibility():
    assert parse(topic="camera/image_raw") == {"topic": "/camera/image_raw", "width": None, "height": None,
                                               "quality": 80, "qos": None, "msg_type": None}
    parsed = parse(topic="/c", width="320", height="0", quality="50", qos_profile="sensor_data", type="mjpeg")
    assert (parsed["width"], parsed["height"], parsed["quality"], parsed["qos"]) == (320, None, 50, "sensor_data")
    assert parse(topic="/c", width="-1")["width"] is None
    assert parse(topic="/c", type="sensor_msgs/msg/CompressedImage")["msg_type"] == "sensor_msgs/msg/CompressedImage"


@pytest.mark.parametrize("args, code", [
    ({}, "missing_field"),
    ({"topic": "/a//b"}, "bad_topic"),
    ({"topic": "/9lives"}, "bad_topic"),
    ({"topic": "/c", "width": "abc"}, "bad_type"),
    ({"topic": "/c", "width": "1.5"}, "bad_type"),
    ({"topic": "/c", "width": "5000"}, "out_of_range"),
    ({"topic": "/c", "height": "-5"}, "out_of_range"),
    ({"topic": "/c", "quality": "0"}, "out_of_range"),
    ({"topic": "/c", "quality": "101"}, "out_of_range"),
    ({"topic": "/c", "qos_profile": "fast"}, "bad_value"),
    ({"topic": "/c", "type": "vp8"}, "unsupported_stream_type"),
])
def test_bad_stream_arguments(args, code):
    with pytest.raises(InvalidInput) as info:
        parse(**args)
    assert info.value.code == code


def test_one_source_feeds_every_output_of_a_topic_with_one_numbering():
    from rover_web.camera.stream import FrameSource, SourceKey

    source = FrameSource(SourceKey("/cam", "sensor_msgs/msg/Image", "default"))
    full = FrameProducer(KEY, CountingEncoder())
    source.attach(full)
    for n in range(1, 4):
        source.put(n)
    seq, jpeg = full.next_frame(0, 1.0)
    assert (seq, jpeg.stamp) == (3, 3.0)
    # A viewer stepping down to a smaller output keeps its place: the new output starts from the
    # newest message (no wait for the next one), numbered as before, so it is not sent twice.
    small = FrameProducer(KEY._replace(width=160, quality=40), CountingEncoder())
    source.attach(small)
    assert small.next_frame(0, 1.0)[0] == 3
    assert small.next_frame(seq, 0.05) is None
    source.put(4)
    assert small.next_frame(seq, 1.0)[1].stamp == 4.0 and full.next_frame(seq, 1.0)[1].stamp == 4.0
    small.put(2, 2)  # an older message never replaces a newer one
    assert small.latest()[0] == 4
    assert source.detach(small) == 1 and source.detach(full) == 0
