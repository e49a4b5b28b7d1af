"""A recording's frames: an MCAP with /tf and /tf_static (written as rosbag2 writes them) shows its tree
and answers lookups at a time of the recording; a file from elsewhere (rosbags' writer, TF on another
topic name) shows its frames; the page renders them."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
import requests

from tests.support.mcap_files import upload

T0 = 1_764_000_000.0
ROOT = Path(__file__).resolve().parents[3]
# shared/ lies beside the checkout (CI, the main checkout), or beside the folder of worktrees.
FOREIGN = next((p for p in (ROOT.parent / "shared", ROOT.parent.parent / "shared") if p.is_dir()),
               ROOT.parent / "shared") / "data" / "foreign_mcap" / "rosbags-rs__test_bag_94types__rosbags-0.10.10.mcap"


def _tf(parent, child, s, xyz, yaw):
    from geometry_msgs.msg import TransformStamped

    t = TransformStamped()
    stamp = T0 + s
    t.header.stamp.sec, t.header.stamp.nanosec = int(stamp), int(round((stamp - int(stamp)) * 1e9))
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return t


def write_tf_run(path: Path) -> Path:
    """/tf_static once at the start (map -> odom, base_link -> laser); /tf 20 Hz for 30 s: odom -> base_link
    at x = s, yaw 0."""
    from mcap.writer import CompressionType, Writer
    from rclpy.serialization import serialize_message
    from tf2_msgs.msg import TFMessage

    from rover_web.recording.schema import schema_text

    with open(path, "wb") as f:
        writer = Writer(f, chunk_size=32 * 1024, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="rover_web tests")
        schema = writer.register_schema("tf2_msgs/msg/TFMessage", "ros2msg",
                                        schema_text("tf2_msgs/msg/TFMessage").encode())
        static = writer.register_channel("/tf_static", "cdr", schema)
        dynamic = writer.register_channel("/tf", "cdr", schema)
        ns = lambda s: int(round((T0 + s) * 1e9))  # noqa: E731
        writer.add_message(static, log_time=ns(0), publish_time=ns(0), data=serialize_message(TFMessage(transforms=[
            _tf("map", "odom", 0, (5.0, 0.0, 0.0), math.pi / 2), _tf("base_link", "laser", 0, (0.2, 0.0, 0.1), 0)])))
        for i in range(600):
            s = i / 20
            message = TFMessage(transforms=[_tf("odom", "base_link", s, (s, 0, 0), 0)])
            writer.add_message(dynamic, log_time=ns(s), publish_time=ns(s), data=serialize_message(message))
        writer.finish()
    return path


@pytest.fixture
def uploaded(live_server, tmp_path):
    answer = upload(live_server, write_tf_run(tmp_path / "tf.mcap"), name="tf run")
    assert answer.status_code == 201, answer.text
    return live_server, answer.json()["id"]


def get(server, recording_id, what, **params):
    return requests.get(f"{server.url}/api/recordings/{recording_id}/{what}", params=params, timeout=30)


def test_a_recordings_frames_at_a_time_and_lookups_through_them(uploaded):
    server, rid = uploaded
    tree = get(server, rid, "tf", t=T0 + 20).json()
    assert tree["tf_topics"] == {"/tf": False, "/tf_static": True}
    assert tree["roots"] == ["map"] and tree["warnings"] == []
    base = tree["frames"]["base_link"]
    # What a listener held at s = 20: the 10 s cache window, 20 Hz.
    assert (base["oldest_stamp"], base["newest_stamp"]) == (pytest.approx(T0 + 10), pytest.approx(T0 + 20))
    assert base["rate_hz"] == pytest.approx(20.0) and base["age_s"] == pytest.approx(0.0, abs=1e-6)
    assert tree["frames"]["laser"]["static"] is True
    # map -> odom turns 90°: the robot at odom x = 12.5 is at map (5, 12.5); the laser 0.2 further along +y.
    got = get(server, rid, "tf/lookup", t=T0 + 20, target="map", source="laser", time=T0 + 12.5).json()
    assert got["translation"] == pytest.approx([5.0, 12.7, 0.1], abs=1e-6)
    assert got["yaw"] == pytest.approx(math.pi / 2)
    latest = get(server, rid, "tf/lookup", t=T0 + 20, target="map", source="base_link").json()
    assert latest["stamp"] == pytest.approx(T0 + 20) and latest["translation"] == pytest.approx([5.0, 20.0, 0.0])
    old = get(server, rid, "tf/lookup", t=T0 + 20, target="map", source="base_link", time=T0 + 5)
    assert old.status_code == 409 and old.json()["error"] == "extrapolation_past"
    assert old.json()["detail"]["by_s"] == pytest.approx(5.0, abs=1e-6)
    # No t: the end of the recording.
    assert get(server, rid, "tf").json()["frames"]["base_link"]["newest_stamp"] == pytest.approx(T0 + 29.95)
    # Before the first dynamic transform only the static tree is known.
    early = get(server, rid, "tf", t=T0 - 1).json()
    assert early["frames"] == {}
    assert get(server, rid, "tf", t="soon").status_code == 400
    assert get(server, rid, "tf/lookup", t=T0 + 20, target="map").status_code == 400
    assert get(server, "nope", "tf").status_code == 404
    page = requests.get(f"{server.url}/recordings/{rid}/tf", params={"t": T0 + 20}, timeout=10)
    assert page.status_code == 200 and "laser" in page.text and "/tf_static (static)" in page.text


@pytest.mark.skipif(not FOREIGN.exists(), reason="the shared foreign MCAP files are not beside the checkout")
def test_a_file_from_elsewhere_shows_its_frames(live_server):
    answer = upload(live_server, FOREIGN, name="rosbags' test bag")
    assert answer.status_code == 201, answer.text
    rid = answer.json()["id"]
    tree = get(live_server, rid, "tf").json()
    assert tree["tf_topics"] == {"/test/tf2_msgs/tf_message": False}
    assert tree["frames"]["child_frame"]["parent"] == "test_frame"
    got = get(live_server, rid, "tf/lookup", target="test_frame", source="child_frame").json()
    assert got["translation"] == [1.0, 2.0, 3.0] and got["rotation"] == [0.0, 0.0, 0.0, 1.0]


def test_flask_replay_of_a_tf_recording_reaches_the_live_tf_page(live_server, tmp_path):
    """`flask replay` republishes the file: /tf_static transient local (tf2's listeners take nothing
    else), /tf as recorded; the running server's TF page shows both."""
    import subprocess
    import sys

    from rover_web.config import ROOT
    from tests.support.rospeer import subprocess_env

    path = write_tf_run(tmp_path / "tf.mcap")
    done = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "replay", str(path), "--rate", "10",
                           "--delay", "2"], cwd=ROOT, env=subprocess_env(), capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    tree = requests.get(live_server.url + "/api/tf", timeout=5).json()
    assert tree["frames"]["laser"]["static"] is True and tree["frames"]["laser"]["parent"] == "base_link"
    assert tree["frames"]["base_link"]["newest_stamp"] == pytest.approx(T0 + 29.95)
    got = requests.get(live_server.url + "/api/tf/lookup", params={"target": "map", "source": "laser"},
                       timeout=5).json()
    assert got["translation"] == pytest.approx([5.0, 30.15, 0.1], abs=1e-6)  # odom x = 29.95, turned 90°
