"""Uploading an MCAP file from elsewhere to replay it: a good file is listed as uploaded; a cut,
damaged, non-MCAP or too large one is a clear 4xx and leaves nothing in the recordings folder."""

from __future__ import annotations

from pathlib import Path

import requests
from mcap.writer import Writer

from rover_web.recording.file_index import walk
from tests.support.mcap_files import upload, write_run


def folder_of(server) -> Path:
    return Path(server.app.config["ROVER_WEB_RECORDINGS_DIR"])


def left_in(server) -> list[str]:
    """Every file in the recordings folder, .incoming/ included."""
    return sorted(str(p.relative_to(folder_of(server))) for p in folder_of(server).rglob("*") if p.is_file())


def refused(answer) -> tuple[int, str]:
    assert answer.headers["Content-Type"] == "application/json", answer.text
    return answer.status_code, answer.json()["error"]


def corrupted(good: Path, into: Path) -> Path:
    """The same length, a few bytes changed in the middle of the first chunk's compressed data."""
    index = walk(good)
    data = bytearray(good.read_bytes())
    middle = index.chunks[0].offset + 9 + 8 * 3 + 4 + 4 + 3 + 8 + 200  # record head, times, sizes, crc, "lz4", length
    data[middle:middle + 16] = bytes(b ^ 0x5A for b in data[middle:middle + 16])
    into.write_bytes(bytes(data))
    return into


def json_only_mcap(into: Path) -> Path:
    with open(into, "wb") as f:
        writer = Writer(f)
        writer.start(profile="", library="elsewhere")
        schema = writer.register_schema("Note", "jsonschema", b'{"type": "object"}')
        channel = writer.register_channel("/notes", "json", schema)
        writer.add_message(channel, log_time=1, publish_time=1, data=b'{"text": "hi"}')
        writer.finish()
    return into


def test_a_good_file_is_stored_whole_and_listed_as_uploaded(live_server, tmp_path):
    good = write_run(tmp_path / "run.mcap")
    answer = upload(live_server, good, name="dock trial (other robot)")
    assert answer.status_code == 201, answer.text
    made = answer.json()
    assert (made["source"], made["name"], made["state"], made["size"]) == \
           ("uploaded", "dock trial (other robot)", "stopped", good.stat().st_size)
    assert made["counts"]["/odom"] == 200 and made["topics"]["/odom"] == "nav_msgs/msg/Odometry"
    assert made["messages"] == 382 and made["duration_s"] == 9.95
    listed = requests.get(live_server.url + "/api/recordings", timeout=5).json()["recordings"]
    assert [(r["id"], r["source"]) for r in listed] == [(made["id"], "uploaded")]
    assert left_in(live_server) == [f"{made['id']}.mcap"]
    assert requests.get(live_server.url + made["file"], timeout=10).content == good.read_bytes()
    assert requests.get(f"{live_server.url}/recordings/{made['id']}/replay", timeout=5).status_code == 200


def test_a_cut_damaged_or_foreign_file_is_a_clear_4xx_and_leaves_nothing(live_server, tmp_path):
    good = write_run(tmp_path / "run.mcap")
    data = good.read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(data[: len(data) // 2])
    garbage = tmp_path / "garbage.mcap"
    garbage.write_bytes(b"PK\x03\x04 not a recording at all " * 100)
    empty = tmp_path / "empty.mcap"
    empty.write_bytes(b"")
    cases = {cut: (422, "truncated"), garbage: (422, "not_mcap"), empty: (422, "not_mcap"),
             corrupted(good, tmp_path / "corrupt.mcap"): (422, "corrupt"),
             json_only_mcap(tmp_path / "json.mcap"): (422, "not_ros2")}
    for path, expected in cases.items():
        answer = upload(live_server, path)
        assert refused(answer) == expected, (path.name, answer.text)
        assert answer.json()["message"]
    wrong_type = requests.post(live_server.url + "/api/recordings/upload", data=data, timeout=10,
                               headers={"Content-Type": "text/plain"})
    assert refused(wrong_type) == (415, "unsupported_media_type")
    bad_name = requests.post(live_server.url + "/api/recordings/upload", params={"name": "a\nb"}, data=data,
                             timeout=10, headers={"Content-Type": "application/octet-stream"})
    assert refused(bad_name) == (400, "bad_name")
    assert left_in(live_server) == []
    assert requests.get(live_server.url + "/api/recordings", timeout=5).json()["recordings"] == []


def test_a_file_over_the_upload_limit_is_refused_before_and_while_it_is_read(live_server_factory, tmp_path):
    server = live_server_factory(ROVER_WEB_RECORDING_UPLOAD_MAX_MB=0.02)  # 20 KiB; the run is ~45 KB
    good = write_run(tmp_path / "run.mcap")
    answer = upload(server, good)
    assert refused(answer) == (413, "upload_too_large") and "ROVER_WEB_RECORDING_UPLOAD_MAX_MB" in \
        answer.json()["message"]

    def chunks():  # no Content-Length: the limit is met while the body streams in
        data = good.read_bytes()
        for i in range(0, len(data), 4096):
            yield data[i:i + 4096]
    streamed = requests.post(server.url + "/api/recordings/upload", data=chunks(), timeout=10,
                             headers={"Content-Type": "application/octet-stream"})
    assert refused(streamed) == (413, "upload_too_large")
    assert left_in(server) == []


def test_an_upload_counts_towards_the_folder_quota(live_server_factory, tmp_path):
    server = live_server_factory(ROVER_WEB_RECORDINGS_MAX_MB=0.03)
    answer = upload(server, write_run(tmp_path / "run.mcap"))
    assert refused(answer) == (507, "folder_full") and left_in(server) == []


def test_what_an_upload_cut_by_a_crash_left_is_removed_at_start(app_factory, tmp_path):
    incoming = tmp_path / "crashed" / ".incoming"
    incoming.mkdir(parents=True)
    (incoming / "0123.part").write_bytes(b"\x89MCAP0\r\n half")
    app_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "crashed"))
    assert list(incoming.iterdir()) == []


def test_operators_upload_viewers_only_replay(signed_server, tmp_path):
    from tests.support.auth import bearer

    good = write_run(tmp_path / "run.mcap")
    assert upload(signed_server, good, headers=bearer(signed_server, "viewer")).status_code == 403
    made = upload(signed_server, good, headers=bearer(signed_server, "operator"))
    assert made.status_code == 201, made.text
    assert made.json()["started_by"] == "operator"
    viewer = bearer(signed_server, "viewer")
    for what, params in (("timeline", {}), ("diagnostics", {"t": 1}), ("fields", {"topic": "/odom"})):
        answer = requests.get(f"{signed_server.url}/api/recordings/{made.json()['id']}/{what}", params=params,
                              headers=viewer, timeout=10)
        assert answer.status_code == 200, (what, answer.text)


def test_the_part_file_is_private_from_its_creation(tmp_path):
    import io
    import os

    from rover_web.recording.upload import _copy

    old = os.umask(0o022)  # a usual umask: open()'s default mode would leave the file 0644
    try:
        _copy(io.BytesIO(b"some bytes"), tmp_path / "x.part", 100)
    finally:
        os.umask(old)
    assert (tmp_path / "x.part").stat().st_mode & 0o777 == 0o600


def test_the_review_s_hostile_files_are_refused_with_the_bound_named(live_server, tmp_path):
    from tests.support import hostile_mcap as hostile

    mib = 1 << 20
    cases = {hostile.zstd_bomb(tmp_path / "zstd.mcap", held=200 * mib): "chunk_too_large",
             hostile.lz4_bomb(tmp_path / "lz4.mcap", held=200 * mib): "chunk_too_large",
             hostile.many_fields(tmp_path / "fields.mcap"): "schema_too_large",
             hostile.many_fields(tmp_path / "fields3k.mcap", fields=3000): "schema_too_many_fields",
             hostile.many_chunks(tmp_path / "chunks.mcap"): "read_budget",
             hostile.amplification(tmp_path / "amplify.mcap"): "not_ros2"}  # nothing it holds can be decoded
    for path, code in cases.items():
        answer = upload(live_server, path)
        assert refused(answer) == (422, code), (path.name, answer.text)
    assert left_in(live_server) == []


def test_an_uploaded_file_s_summary_is_not_believed(live_server, tmp_path):
    from rover_web.recording import file_index
    from tests.support import hostile_mcap as hostile

    path = hostile.attachment_bomb(tmp_path / "attachment.mcap", held=100 * (1 << 20))
    answer = upload(live_server, path)
    assert answer.status_code == 201, answer.text
    made = answer.json()
    file_index.forget(folder_of(live_server) / f"{made['id']}.mcap")  # as after a restart: the index is built again
    timeline = requests.get(f"{live_server.url}/api/recordings/{made['id']}/timeline", timeout=20)
    assert timeline.status_code == 200, timeline.text
    walked = file_index.index_of(folder_of(live_server) / f"{made['id']}.mcap")  # the one the timeline built
    assert [c.offset for c in walked.chunks] == [c.offset for c in file_index.walk(path).chunks]  # not the attachment
