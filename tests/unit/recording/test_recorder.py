"""The Recorder without ROS: a full queue drops and counts, limits stop it and say why, and a file
cut anywhere reads back as a prefix of what was written."""

from __future__ import annotations

import random
import time

import pytest
from rclpy.serialization import serialize_message
from std_msgs.msg import String

from rover_web.recording.reading import NotARecording, Outcome, read_messages
from rover_web.recording.recorder import Limits, Recorder

ROOMY = Limits(max_bytes=10**9, folder_bytes_other=0, folder_max_bytes=10**10, min_free_bytes=0)


def cdr(text: str) -> bytes:
    return serialize_message(String(data=text))


def make(tmp_path, limits=ROOMY, queue_size=1000, name="r.mcap") -> Recorder:
    return Recorder(tmp_path / name, {"/a": "std_msgs/msg/String"}, limits=limits, queue_size=queue_size,
                    metadata={"id": "r"})


def texts(path, outcome=None) -> list[str]:
    return [_decode(m.data) for _s, c, m in read_messages(path, outcome) if c.topic == "/a"]


def _decode(data: bytes) -> str:
    from rclpy.serialization import deserialize_message
    return deserialize_message(data, String).data


def test_a_finished_file_has_every_message_and_a_footer(tmp_path):
    rec = make(tmp_path)
    for i in range(500):
        assert rec.offer("/a", cdr(f"m{i}"))
    rec.stop("requested")
    outcome = Outcome()
    assert texts(tmp_path / "r.mcap", outcome) == [f"m{i}" for i in range(500)]
    assert outcome.complete and rec.stop_reason == "requested" and rec.counts["/a"] == 500


def test_a_file_cut_anywhere_reads_as_a_prefix_of_what_was_written(tmp_path):
    rec = make(tmp_path, queue_size=10000)
    sent = [f"message {i} " + random.Random(i).randbytes(600).hex() for i in range(3000)]  # 4 chunks of 1 MB
    for text in sent:
        assert rec.offer("/a", cdr(text))
    rec.stop("requested")
    whole = (tmp_path / "r.mcap").read_bytes()
    for cut in (len(whole) // 2, len(whole) * 9 // 10):
        cut_path = tmp_path / f"cut{cut}.mcap"
        cut_path.write_bytes(whole[:cut])
        outcome = Outcome()
        got = texts(cut_path, outcome)
        assert got == sent[:len(got)] and not outcome.complete
        assert 0 < len(got) < len(sent)
    (tmp_path / "head.mcap").write_bytes(whole[:100])  # not even its first chunk survived
    with pytest.raises(NotARecording):
        list(read_messages(tmp_path / "head.mcap"))


def test_a_full_queue_drops_and_counts_instead_of_waiting(tmp_path):
    rec = make(tmp_path, queue_size=100)
    started = time.monotonic()
    data = cdr("y" * 1000)
    results = [rec.offer("/a", data) for _ in range(20000)]
    assert time.monotonic() - started < 5  # never blocked on the writer
    rec.stop("requested")
    assert rec.dropped["/a"] == results.count(False) > 0
    assert rec.counts["/a"] == results.count(True)


@pytest.mark.parametrize(("limits", "reason"), [
    (Limits(max_bytes=1, folder_bytes_other=0, folder_max_bytes=10**10, min_free_bytes=0), "max_size"),
    (Limits(max_bytes=10**9, folder_bytes_other=5000, folder_max_bytes=5001, min_free_bytes=0), "folder_full"),
    (Limits(max_bytes=10**9, folder_bytes_other=0, folder_max_bytes=10**10, min_free_bytes=10**18), "disk_low"),
])
def test_each_limit_stops_the_recording_cleanly_and_says_why(tmp_path, limits, reason):
    rec = make(tmp_path, limits=limits)
    rec.offer("/a", cdr("one"))
    deadline = time.monotonic() + 5
    while rec.running:
        assert time.monotonic() < deadline
        time.sleep(0.05)
    assert rec.stop_reason == reason and not rec.offer("/a", cdr("late"))
    outcome = Outcome()
    assert texts(tmp_path / "r.mcap", outcome) == ["one"] and outcome.complete


@pytest.mark.parametrize("content", [b"", b"not an mcap file at all", b"\x89MCAP0\r\n\x01\x02"])
def test_anything_but_a_recording_is_refused_with_a_reason(tmp_path, content):
    path = tmp_path / "bad.mcap"
    path.write_bytes(content)
    with pytest.raises(NotARecording):
        list(read_messages(path))
    with pytest.raises(NotARecording):
        list(read_messages(tmp_path / "missing.mcap"))
