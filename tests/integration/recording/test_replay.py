"""`flask --app rover_web replay FILE`: a recording's messages reach a ROS node in another process,
equal and with their original timing (scaled by --rate); a non-MCAP or cut file is one clear message
and a non-zero exit."""

from __future__ import annotations

import subprocess
import sys

from rclpy.serialization import serialize_message
from std_msgs.msg import String

from rover_web.config import ROOT
from rover_web.recording.recorder import Limits, Recorder
from tests.support.rospeer import subprocess_env

ROOMY = Limits(max_bytes=10**9, folder_bytes_other=0, folder_max_bytes=10**10, min_free_bytes=0)
STEP_NS = 200_000_000  # 0.2 s between recorded messages
N = 8


def recording(path, texts, topic="/replay/chatter"):
    rec = Recorder(path, {topic: "std_msgs/msg/String", "/rover_web/audit": "std_msgs/msg/String"}, limits=ROOMY,
                   queue_size=100, metadata={"id": "t"})
    t0 = 1_700_000_000_000_000_000
    for i, text in enumerate(texts):
        rec.offer(topic, serialize_message(String(data=text)), t0 + i * STEP_NS)
    rec.offer("/rover_web/audit", serialize_message(String(data='{"action": "x"}')), t0)
    rec.stop("requested")
    return path


def replay(*args, timeout=30):
    return subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "replay", *map(str, args)], cwd=ROOT,
                          env=subprocess_env(), capture_output=True, text=True, timeout=timeout)


def test_replay_publishes_every_message_with_its_timing_scaled_by_the_rate(ros_peer, tmp_path):
    texts = [f"replayed {i}" for i in range(N)]
    path = recording(tmp_path / "r.mcap", texts)
    peer = ros_peer("replay_listener")
    peer.subscribe("/replay/chatter", "std_msgs/msg/String", qos=50)
    peer.subscribe("/rover_web/audit", "std_msgs/msg/String", qos=50)
    done = replay(path, "--rate", "2", "--delay", "3")  # time to match on a loaded machine
    assert done.returncode == 0, done.stderr
    assert f"replayed {N} messages" in done.stdout
    peer.wait_for("/replay/chatter", lambda m: m["data"] == texts[-1], timeout=5)  # its stdout lags
    got = peer.received("/replay/chatter")
    assert [m["msg"]["data"] for m in got] == texts
    # 0.2 s recorded at rate 2: 0.1 s apart, the whole run 0.7 s. Read from when the replay published
    # each one (the source timestamp), not when the listener took it: a loaded machine holds the
    # listener, not the replay's clock. Rate 1 would double both; none would halve them.
    gaps = sorted(b["sent"] - a["sent"] for a, b in zip(got, got[1:], strict=False))
    assert 0.07 < gaps[len(gaps) // 2] < 0.14, gaps
    assert 0.5 < got[-1]["sent"] - got[0]["sent"] < 1.2, gaps
    assert peer.received("/rover_web/audit") == []  # never a ROS topic: not replayed unless asked for


def test_a_file_that_is_not_a_recording_is_one_clear_message_and_a_failure(tmp_path):
    text = tmp_path / "notes.mcap"
    text.write_text("not a recording\n")
    done = replay(text)
    assert done.returncode != 0 and done.stderr.strip().splitlines() == \
        [f"Error: {text} is not an MCAP file (it does not start with the MCAP magic bytes)"]
    missing = replay(tmp_path / "missing.mcap")
    assert missing.returncode != 0 and "does not exist" in missing.stderr


def test_a_cut_file_replays_what_survived_and_then_fails_saying_so(tmp_path):
    whole = recording(tmp_path / "whole.mcap", [f"m{i}" for i in range(3)]).read_bytes()
    cut = tmp_path / "cut.mcap"
    cut.write_bytes(whole[:len(whole) - 200])  # the summary and footer are gone, the chunk is there
    done = replay(cut, "--rate", "100", "--delay", "0")
    assert done.returncode == 1 and "replayed 3 messages" in done.stdout
    assert done.stderr.strip() == f"Error: {cut} was cut short (no footer): replayed up to its last complete chunk"
    head = tmp_path / "head.mcap"
    head.write_bytes(whole[:60])
    done = replay(head, "--delay", "0")
    assert done.returncode == 1 and "damaged before its first message" in done.stderr


def motion_recording(path):
    from geometry_msgs.msg import Twist
    from std_msgs.msg import Bool

    rec = Recorder(path, {"/replay/chatter": "std_msgs/msg/String", "/cmd_vel": "geometry_msgs/msg/Twist",
                          "/e_stop": "std_msgs/msg/Bool", "/nav/cmd": "geometry_msgs/msg/Twist"},
                   limits=ROOMY, queue_size=100, metadata={"id": "t"})
    t0 = 1_700_000_000_000_000_000
    for i in range(N):
        rec.offer("/replay/chatter", serialize_message(String(data=f"m{i}")), t0 + i * STEP_NS)
        rec.offer("/cmd_vel", serialize_message(Twist()), t0 + i * STEP_NS)
        rec.offer("/nav/cmd", serialize_message(Twist()), t0 + i * STEP_NS)
        rec.offer("/e_stop", serialize_message(Bool(data=False)), t0 + i * STEP_NS)
    rec.stop("requested")
    return path


def test_replay_leaves_motion_and_safety_out_unless_asked(ros_peer, tmp_path):
    path = motion_recording(tmp_path / "m.mcap")
    peer = ros_peer("replay_motion_listener")
    for topic, type_name in (("/replay/chatter", "std_msgs/msg/String"), ("/cmd_vel", "geometry_msgs/msg/Twist"),
                             ("/nav/cmd", "geometry_msgs/msg/Twist"), ("/e_stop", "std_msgs/msg/Bool")):
        peer.subscribe(topic, type_name, qos=50)
    done = replay(path, "--rate", "4", "--delay", "3")
    assert done.returncode == 0, done.stderr
    assert "skipping /cmd_vel" in done.stderr and "skipping /e_stop" in done.stderr
    assert "--include-motion" in done.stderr
    peer.wait_for("/replay/chatter", lambda m: m["data"] == f"m{N - 1}", timeout=5)
    assert peer.received("/cmd_vel") == [] and peer.received("/e_stop") == [] and peer.received("/nav/cmd") == []
    done = replay(path, "--rate", "4", "--delay", "3", "--include-motion")
    assert done.returncode == 0, done.stderr
    peer.wait_for("/e_stop", lambda m: m["data"] is False, timeout=5)
    peer.wait_for("/cmd_vel", lambda m: True, timeout=5)
    peer.wait_for("/nav/cmd", lambda m: True, timeout=5)


def test_a_file_over_a_reading_bound_is_refused_before_anything_is_published(tmp_path):
    from tests.support import hostile_mcap as hostile

    path = hostile.zstd_bomb(tmp_path / "bomb.mcap", held=200 * (1 << 20))  # its one message is in the bomb
    done = replay(path, "--delay", "0")
    assert done.returncode == 1, done.stdout
    assert "Error:" in done.stderr and "chunk" in done.stderr and "replayed" not in done.stdout
