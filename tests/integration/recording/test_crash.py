"""A recording cut by SIGKILL: a served app in its own process records a peer's topic, is killed,
and the file is read (no summary, no footer) up to its last complete chunk; the restarted app
lists it as interrupted."""

from __future__ import annotations

import signal
import time

import requests
from mcap_ros2.decoder import DecoderFactory

from rover_web.recording.reading import Outcome, read_messages
from tests.support.waiting import wait_until

from .helpers import STRING, start, status, wait_listed

N = 30


def test_a_recording_cut_by_sigkill_is_readable_up_to_its_last_chunk(server_process, ros_peer, tmp_path):
    env = {"ROVER_WEB_DB_PATH": str(tmp_path / "app.sqlite3"), "ROVER_WEB_RECORDINGS_DIR": str(tmp_path / "rec")}
    server = server_process(env=env).start()
    peer = ros_peer("crash_peer")
    peer.advertise("/crash/chatter", STRING)
    wait_listed(server, "/crash/chatter")
    started = start(server, {"topics": ["/crash/chatter"]})
    peer.wait_match("/crash/chatter", 1)
    sent = [f"before the crash {i}" for i in range(N)]
    for text in sent:
        peer.publish("/crash/chatter", {"data": text})
    wait_until(lambda: status(server, started["id"])["counts"].get("/crash/chatter") == N, 15, "all written")
    # The writer closes a chunk and hands it to the OS at least every second (recorder.FLUSH_S);
    # the size the status shows is the file's after such a flush.
    written = wait_until(lambda: (s := status(server, started["id"]))["size"] > 0 and
                         s["counts"].get("/crash/chatter") == N and s, 10, "flushed")
    time.sleep(1.5)  # one more flush after the last message was written
    assert written["state"] == "recording"
    server.stop(signal.SIGKILL)

    path = tmp_path / "rec" / f"{started['id']}.mcap"
    outcome = Outcome()
    decoder = DecoderFactory()
    got = []
    for schema, channel, message in read_messages(path, outcome):
        if channel.topic == "/crash/chatter":
            got.append(decoder.decoder_for(channel.message_encoding, schema)(message.data).data)
    assert not outcome.complete  # no footer: the process never finished the file
    assert got == sent

    # The restarted app lists it, interrupted, with the counts of its last flush.
    again = server_process(env=env).start()
    listed = requests.get(again.url + "/api/recordings", timeout=5).json()["recordings"]
    assert [(r["id"], r["state"], r["stop_reason"]) for r in listed] == [(started["id"], "interrupted", "interrupted")]
    assert listed[0]["counts"]["/crash/chatter"] == N
    assert requests.get(again.url + listed[0]["file"], timeout=10).content == path.read_bytes()
