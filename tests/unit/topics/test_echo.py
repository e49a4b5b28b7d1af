"""Topic echo: measured rate and bandwidth, throttled shared decoding, truncation of big fields."""

import array
import json
import time

import pytest

from rover_web.topics.echo import TopicEcho, TrafficMeter, clip_strings


def test_rate_and_bandwidth_over_the_window():
    meter = TrafficMeter(window_s=5.0)
    for i in range(101):  # 20 Hz for 5 s, 1000-byte messages
        meter.record(1000, now=10.0 + i * 0.05)
    snap = meter.snapshot(now=15.0)
    assert snap["rate_hz"] == pytest.approx(20.0, rel=1e-3)
    assert snap["bandwidth_bps"] == pytest.approx(20000.0, rel=1e-3)
    assert snap["count"] == 101 and snap["size_bytes"] == 1000 and snap["bytes_total"] == 101000


def test_rate_falls_when_the_topic_goes_quiet():
    meter = TrafficMeter(window_s=5.0)
    for i in range(21):
        meter.record(10, now=i * 0.05)  # 20 Hz for 1 s
    assert meter.snapshot(now=1.0)["rate_hz"] == pytest.approx(20.0)
    quiet = meter.snapshot(now=3.0)
    assert quiet["rate_hz"] < 10.0 and quiet["age_s"] == 2.0
    assert meter.snapshot(now=100.0)["rate_hz"] == 0.0


def test_never_heard():
    snap = TrafficMeter().snapshot(now=1.0)
    assert snap == {"count": 0, "bytes_total": 0, "rate_hz": 0.0, "bandwidth_bps": 0.0, "size_bytes": None,
                    "age_s": None}


def test_echo_decodes_at_most_max_hz_whatever_the_message_rate():
    decoded = []

    def decode(raw):
        decoded.append(raw)
        return {"n": int(raw)}

    echo = TopicEcho("/fast", "std_msgs/msg/Int32", decode, max_hz=5.0)
    now = 0.0
    for i in range(1, 1001):  # 1000 messages over 10 s, viewers asking after every one
        echo.put(str(i).encode())
        for _viewer in range(3):
            echo.sample(now=now)
        now += 0.01
    assert 45 <= echo.decodes <= 56  # ~5 a second for 10 s, shared by the three viewers
    assert echo.meter.count == 1000  # every message still counted for rate and bandwidth
    seq, fields, error = echo.sample(now=now + 1)
    assert seq == 1000 and fields == {"n": 1000} and error is None


def test_echo_reports_decode_failures_and_keeps_going():
    def decode(raw):
        raise ValueError("bad CDR")

    echo = TopicEcho("/x", "pkg/msg/T", decode, max_hz=10.0)
    echo.put(b"\x00")
    seq, fields, error = echo.sample()
    assert seq == 1 and fields is None and "bad CDR" in error and "pkg/msg/T" in error


def test_wait_newer():
    echo = TopicEcho("/x", "pkg/msg/T", lambda raw: {}, max_hz=10.0)
    assert echo.wait_newer(0, 0.01) is False
    echo.put(b"a")
    assert echo.wait_newer(0, 0.01) is True and echo.wait_newer(1, 0.01) is False


def test_long_strings_are_cut_with_their_length():
    clipped = clip_strings({"data": "x" * 5000, "list": ["short", "y" * 30]}, max_chars=20)
    assert clipped["data"] == {"truncated": True, "length": 5000, "head": "x" * 20}
    assert clipped["list"][0] == "short" and clipped["list"][1]["length"] == 30


def test_message_to_dict_cuts_big_arrays_fast_and_shows_lengths():
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import Image
    from std_msgs.msg import ByteMultiArray

    from rover_web.ros.convert import message_to_dict

    image = Image()
    image.data = array.array("B", bytes(range(256)) * 16384)  # 4 MiB
    started = time.perf_counter()
    fields = message_to_dict(image, max_items=8)
    assert time.perf_counter() - started < 0.5  # converting 4 M items to Python first took far longer
    assert fields["data"] == {"truncated": True, "length": 4194304, "head": [0, 1, 2, 3, 4, 5, 6, 7]}
    raw_bytes = ByteMultiArray()
    raw_bytes.data = [b"\x01", b"\xff"]
    assert message_to_dict(raw_bytes)["data"] == [1, 255]
    odom = Odometry()
    odom.pose.covariance[1] = float("nan")
    cov = message_to_dict(odom, max_items=4)["pose"]["covariance"]
    assert cov["length"] == 36 and cov["head"][1] == "nan"
    json.dumps(cov, allow_nan=False)


@pytest.mark.parametrize("raw, name", [("/odom", "/odom"), ("camera/image_raw", "/camera/image_raw"),
                                       ("/_hidden/x", "/_hidden/x")])
def test_topic_names_are_fully_qualified(raw, name):
    from rover_web.web.validate import topic_name
    assert topic_name(raw) == name


@pytest.mark.parametrize("raw", ["", "/", "//a", "/a/", "/a b", "/1a", "~/x", "/{node}", "/a" * 200, None, 5])
def test_bad_topic_names(raw):
    from rover_web.web.validate import InvalidInput, topic_name
    with pytest.raises(InvalidInput):
        topic_name(raw)
