"""A recording's chunk map: the same answers from a finished file's summary and from a pass over
it; a file cut short is read up to its last whole chunk; the strict pass (uploads) refuses what is
cut, damaged or not MCAP; the message at a time is found reading only the chunks it needs."""

from __future__ import annotations

import pytest

from rover_web.recording import file_index
from rover_web.recording.file_index import Refused, from_summary, walk
from tests.support.mcap_files import T0, pose_x, write_run


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return write_run(tmp_path_factory.mktemp("index") / "run.mcap")


def test_the_summary_and_a_pass_over_the_file_agree(run):
    summary, walked = from_summary(run), walk(run, strict=True)
    assert summary is not None and summary.complete and walked.complete
    assert summary.counts == walked.counts and summary.topics() == walked.topics()
    assert (summary.start_ns, summary.end_ns) == (walked.start_ns, walked.end_ns) == (T0 * 1e9, (T0 + 9.95) * 1e9)
    assert [(c.offset, c.start_ns, c.end_ns, c.channels) for c in summary.chunks] == \
           [(c.offset, c.start_ns, c.end_ns, c.channels) for c in walked.chunks]
    assert len(summary.chunks) > 3  # the questions below read some chunks, not all


@pytest.mark.parametrize("build", [from_summary, walk], ids=["summary", "pass"])
def test_the_message_at_a_time_is_the_last_one_logged_at_or_before_it(run, build):
    index = build(run)
    for s, expected in ((0.0, 0.0), (4.149, 4.1), (4.15, 4.1), (9.99, 9.9)):
        _channel, message = index.latest("/amcl_pose", int((T0 + s) * 1e9) + (1 if s == 4.15 else 0))
        assert index.decode(message).pose.pose.position.x == pytest.approx(pose_x(expected)), s
    assert index.latest("/amcl_pose", int((T0 - 1) * 1e9)) is None
    assert index.latest("/nowhere", int(T0 * 1e9)) is None
    between = [m.log_time for _c, m in index.messages(["/odom"], int((T0 + 2) * 1e9), int((T0 + 3) * 1e9))]
    assert sorted(between) == [int(round((T0 + 2 + i * 0.05) * 1e9)) for i in range(21)]


def test_a_file_cut_short_is_read_to_its_last_whole_chunk_and_refused_by_the_strict_pass(run, tmp_path):
    data = run.read_bytes()
    whole = walk(run)
    second_chunk_ends = whole.chunks[2].offset  # cut inside the third chunk
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: second_chunk_ends + 100])
    index = file_index.index_of(cut)
    assert not index.complete and len(index.chunks) == 2
    assert index.end_ns < whole.end_ns and index.count(["/odom"]) < whole.count(["/odom"])
    last = index.latest("/odom", whole.end_ns)[1]
    assert last.log_time <= index.end_ns
    with pytest.raises(Refused) as refused:
        walk(cut, strict=True)
    assert refused.value.code == "truncated"


def test_a_damaged_chunk_ends_the_lenient_pass_and_is_refused_by_the_strict_one(run, tmp_path):
    whole = walk(run)
    data = bytearray(run.read_bytes())
    at = whole.chunks[1].offset + 9 + 8 * 3 + 4 + 4 + 3 + 8 + 50
    data[at:at + 8] = bytes(b ^ 0xFF for b in data[at:at + 8])
    damaged = tmp_path / "damaged.mcap"
    damaged.write_bytes(bytes(data))
    assert len(walk(damaged).chunks) == 1
    with pytest.raises(Refused) as refused:
        walk(damaged, strict=True)
    assert refused.value.code == "corrupt"


def test_what_is_not_mcap_is_said_so(tmp_path):
    other = tmp_path / "other.mcap"
    other.write_bytes(b"GIF89a" + bytes(100))
    with pytest.raises(Refused) as refused:
        walk(other, strict=True)
    assert refused.value.code == "not_mcap"
    with pytest.raises(file_index.NotARecording):
        file_index.index_of(other)
