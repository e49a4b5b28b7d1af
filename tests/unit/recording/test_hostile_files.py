"""The third security review's hostile MCAP files (issue 40; tests/support/hostile_mcap.py) meet a bound
wherever they are read: the upload's strict pass, the replay view's index and questions, `flask replay`'s
reader. Held sizes are smaller than the review's but over the caps, so the old code (which accepted
every one of them) is cheap to run against."""

from __future__ import annotations

import time

import pytest

from rover_web.recording import bounds, file_index
from rover_web.recording.bounds import TooCostly
from rover_web.recording.file_index import from_summary, walk
from rover_web.recording.reading import read_messages
from rover_web.recording.timeline import timeline
from tests.support import hostile_mcap as hostile

MIB = 1 << 20


def refused_by(read, path) -> str:
    with pytest.raises(TooCostly) as caught:
        read(path)
    return caught.value.code


def every_read(path) -> set[str]:
    """The bound named by each way the server reads a file."""
    return {refused_by(lambda p: walk(p, strict=True), path), refused_by(walk, path),
            refused_by(lambda p: list(read_messages(p)), path)}


def test_a_zstd_chunk_declaring_more_than_the_cap_is_refused_before_decompressing(tmp_path):
    path = hostile.zstd_bomb(tmp_path / "zstd.mcap", held=200 * MIB)
    started = time.process_time()
    assert every_read(path) == {"chunk_too_large"}
    assert time.process_time() - started < 0.5  # nothing decompressed: refused on the declared size


def test_an_lz4_chunk_holding_more_than_it_declares_is_refused_at_the_first_byte_over(tmp_path):
    path = hostile.lz4_bomb(tmp_path / "lz4.mcap", held=200 * MIB)
    assert every_read(path) == {"chunk_too_large"}


def test_a_chunk_index_pointing_at_an_attachment_opens_nothing(tmp_path):
    path = hostile.attachment_bomb(tmp_path / "attachment.mcap", held=100 * MIB)
    walked = walk(path, strict=True)  # honest apart from its summary: accepted, as before
    assert [m.data for _c, m in walked.messages(["/chatter"])] == [hostile.string_cdr("hello")]
    believed = from_summary(path)  # as a file this server wrote would be read
    assert believed is not None and list(believed.messages(["/chatter"])) == []  # not a chunk there: nothing
    file_index.forget(path)
    untrusted = file_index.index_of(path)  # a file from elsewhere: walked, its summary ignored
    assert [c.offset for c in untrusted.chunks] == [c.offset for c in walked.chunks]


def test_an_array_of_empty_messages_is_not_decoded(tmp_path):
    path = hostile.amplification(tmp_path / "amplify.mcap")
    index = walk(path, strict=True)
    assert index.topics()["/odom"]["decodable"] is False
    started = time.process_time()
    answer = timeline(index)
    assert answer["series"]["odom"] == {} and time.process_time() - started < 1.0


def test_a_message_longer_than_the_decoding_cap_is_not_decoded(tmp_path):
    from mcap.records import Schema

    honest = Schema(id=1, name="std_msgs/msg/UInt8MultiArray", encoding="ros2msg", data=b"uint8[] data\n")
    assert not bounds.amplifies(honest.name, honest.data.decode())
    path = hostile.amplification(tmp_path / "a.mcap", length=1024)
    index = walk(path)
    message = next(m for _c, m in index.messages(["/odom"]))
    assert index.decode(message, most=100) is None


def test_a_schema_with_too_many_fields_never_reaches_the_parser(tmp_path):
    path = hostile.many_fields(tmp_path / "fields.mcap", fields=3000)
    assert every_read(path) == {"schema_too_many_fields"}
    huge = hostile.many_fields(tmp_path / "huge.mcap")  # the review's 200,000 fields: 2 MB of text
    assert every_read(huge) == {"schema_too_large"}


def test_the_total_decompressed_per_read_is_bounded(tmp_path):
    path = hostile.many_chunks(tmp_path / "chunks.mcap")  # 100 chunks of 32 MiB in 114 KB
    started = time.process_time()
    assert every_read(path) == {"read_budget"}
    assert time.process_time() - started < 3 * 2.0  # three reads, each stopped at 1 GiB


def test_a_message_over_the_cap_and_a_read_over_its_time_are_refused(tmp_path, monkeypatch):
    monkeypatch.setattr(bounds, "MESSAGE_MAX", 512)
    path = hostile.amplification(tmp_path / "a.mcap", length=1024)
    assert every_read(path) == {"message_too_large"}
    monkeypatch.setattr(bounds, "MESSAGE_MAX", MIB)
    monkeypatch.setattr(bounds, "TIME_S", -1.0)
    assert refused_by(walk, path) == "time_budget"
