"""Recordings against real ROS nodes in other processes: what the peer published comes back, equal,
through mcap-ros2-support and rosbags; the audit trail is in the same file; bad input creates nothing;
one recording at a time; the list survives a restart; limits stop a recording and say why."""

from __future__ import annotations

import json
import time

import requests
from rclpy.serialization import deserialize_message

from rover_web.ros.convert import dict_to_message
from rover_web.ros.typesupport import message_class
from tests.support.waiting import wait_until

from .helpers import ODOM, STRING, audit_records, read_mcap_ros2, read_rosbags, start, status, stop, wait_listed

N = 12


def odom(i: int) -> dict:
    return {"header": {"stamp": {"sec": 100 + i, "nanosec": 7 * i}, "frame_id": "odom"}, "child_frame_id": "base_link",
            "pose": {"pose": {"position": {"x": 0.5 * i, "y": -1.25, "z": 0.0},
                              "orientation": {"x": 0.0, "y": 0.0, "z": 0.6, "w": 0.8}},
                     "covariance": [float(k) for k in range(36)]},
            "twist": {"twist": {"linear": {"x": 1.0 + i}, "angular": {"z": -0.1 * i}}}}


def test_every_published_message_comes_back_equal_through_both_readers_with_the_audit_trail(
        live_server_factory, ros_peer, tmp_path):
    server = live_server_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "rec"))
    peer = ros_peer("recorded_peer")
    peer.advertise("/rec/chatter", STRING)
    peer.advertise("/rec/odom", ODOM)
    wait_listed(server, "/rec/chatter")
    wait_listed(server, "/rec/odom")
    started = start(server, {"topics": ["/rec/chatter", "rec/odom"], "name": "field run 3"})
    assert started["state"] == "recording" and started["name"] == "field run 3"
    assert started["topics"] == {"/rec/chatter": STRING, "/rec/odom": ODOM, "/rover_web/audit": STRING}
    peer.wait_match("/rec/chatter", 1)
    peer.wait_match("/rec/odom", 1)
    sent_strings = [f"hello {i} ünïcode" for i in range(N)]
    for i in range(N):
        peer.publish("/rec/chatter", {"data": sent_strings[i]})
        peer.publish("/rec/odom", odom(i))
    # Operator actions while recording go into the same file, with who did them.
    assert requests.post(server.url + "/api/estop", json={"engaged": True, "by": "alice"}, timeout=5).ok
    assert requests.post(server.url + "/api/estop", json={"engaged": False, "by": "bob"}, timeout=5).ok
    wait_until(lambda: status(server, started["id"])["counts"] == {"/rec/chatter": N, "/rec/odom": N}
               | {k: v for k, v in status(server, started["id"])["counts"].items() if k == "/rover_web/audit"},
               10, "every message written")
    done = stop(server, started["id"])
    assert done["state"] == "stopped" and done["stop_reason"] == "requested" and done["dropped"] == {}
    listed = requests.get(server.url + "/api/recordings", timeout=5).json()["recordings"]
    assert [r["id"] for r in listed] == [started["id"]] and listed[0]["size"] > 0 and listed[0]["duration_s"] > 0

    path = tmp_path / "rec" / f"{started['id']}.mcap"
    # The file holds CDR that rclpy itself reads back as exactly the message the peer built, every
    # field (not compared byte for byte: CDR alignment padding is not guaranteed to be zeroed).
    from mcap.reader import make_reader
    with open(path, "rb") as f:
        reader = make_reader(f)
        assert reader.get_header().profile == "ros2"
        raw = [m.data for _s, _c, m in reader.iter_messages(topics=["/rec/odom"])]
    assert [deserialize_message(data, message_class(ODOM)) for data in raw] == \
           [dict_to_message(ODOM, odom(i)) for i in range(N)]

    for read in (read_mcap_ros2, read_rosbags):
        found = read(path)
        assert [m.data for m in found["/rec/chatter"]] == sent_strings, read.__name__
        odoms = found["/rec/odom"]
        assert len(odoms) == N, read.__name__
        for i, msg in enumerate(odoms):
            expected = odom(i)
            assert (msg.header.stamp.sec, msg.header.stamp.nanosec, msg.header.frame_id, msg.child_frame_id) == \
                   (100 + i, 7 * i, "odom", "base_link")
            assert msg.pose.pose.position.x == expected["pose"]["pose"]["position"]["x"]
            assert msg.pose.pose.orientation.w == 0.8 and list(msg.pose.covariance) == list(range(36))
            assert msg.twist.twist.linear.x == 1.0 + i and msg.twist.twist.angular.z == -0.1 * i
        actions = [(r["action"], r["by"]) for r in audit_records(found["/rover_web/audit"])]
        assert ("estop.engage", "alice") in actions and ("estop.release", "bob") in actions, actions
        assert actions[0][0] == "recording.start" and actions[-1][0] == "recording.stop", actions

    # The download answers Range (a remote viewer seeks), and whole it is the file.
    whole = requests.get(server.url + done["file"], timeout=10)
    assert whole.status_code == 200 and whole.content == path.read_bytes()
    part = requests.get(server.url + done["file"], headers={"Range": "bytes=0-7"}, timeout=10)
    assert part.status_code == 206 and part.content == b"\x89MCAP0\r\n"


def test_bad_input_is_a_clear_4xx_and_creates_nothing(live_server_factory, tmp_path):
    folder = tmp_path / "rec"
    server = live_server_factory(ROVER_WEB_RECORDINGS_DIR=str(folder))
    bad = [({"topics": "some"}, 400, "bad_topics"), ({"topics": []}, 400, "bad_topics"),
           ({"topics": ["/ok", "bad topic"]}, 400, "bad_topic"), ({"topics": "all", "camera": "yes"}, 400, "bad_type"),
           ({"topics": "all", "name": "a\nb"}, 400, "bad_name"), ({"topics": "all", "extra": 1}, 400, None),
           ({"topics": "preset:nope"}, 400, "unknown_preset"),
           ({"topics": ["/nobody/publishes"]}, 422, "unknown_topic")]
    for body, code, error in bad:
        answer = requests.post(server.url + "/api/recordings", json=body, timeout=5)
        assert answer.status_code == code, (body, answer.text)
        assert answer.json()["message"] and (error is None or answer.json()["error"] == error), answer.json()
    assert requests.post(server.url + "/api/recordings", data="[1]", headers={"Content-Type": "application/json"},
                         timeout=5).status_code == 400
    assert requests.get(server.url + "/api/recordings", timeout=5).json()["recordings"] == []
    assert list(folder.glob("*")) == []
    for path in ("/api/recordings/nope", "/api/recordings/../x", "/api/recordings/nope/file"):
        assert requests.get(server.url + path, timeout=5).status_code == 404


def test_one_recording_at_a_time_and_the_list_survives_a_restart(app_factory, tmp_path):
    settings = {"ROVER_WEB_RECORDINGS_DIR": str(tmp_path / "rec"), "ROVER_WEB_DB_PATH": str(tmp_path / "db.sqlite3")}
    app = app_factory(**settings)
    client = app.test_client()
    first = client.post("/api/recordings", json={"topics": "all", "name": "one"})
    assert first.status_code == 201, first.json
    second = client.post("/api/recordings", json={"topics": "all"})
    assert second.status_code == 409 and second.json["error"] == "recording_in_progress"
    assert client.get(f"{first.json['file']}").status_code == 409  # still being written
    assert client.post(f"/api/recordings/{first.json['id']}/stop", json={}).json["state"] == "stopped"
    app.extensions["rover_web"].shutdown()
    again = app_factory(**settings).test_client()
    listed = again.get("/api/recordings").json["recordings"]
    assert [(r["id"], r["name"], r["state"]) for r in listed] == [(first.json["id"], "one", "stopped")]
    assert again.delete(f"/api/recordings/{first.json['id']}").status_code == 200  # sign-in off: admin
    assert again.get("/api/recordings").json["recordings"] == [] and list((tmp_path / "rec").glob("*")) == []


def test_the_size_limit_stops_the_recording_cleanly_and_says_why(live_server_factory, ros_peer, tmp_path):
    server = live_server_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "rec"), ROVER_WEB_RECORDING_MAX_MB=0.02)
    peer = ros_peer("big_peer")
    peer.advertise("/rec/big", STRING)
    wait_listed(server, "/rec/big")
    started = start(server, {"topics": ["/rec/big"]})
    peer.wait_match("/rec/big", 1)
    filler = "".join(chr(0x41 + (i * 7919) % 57) for i in range(4000))  # poorly compressible
    deadline = time.monotonic() + 20
    while status(server, started["id"])["state"] == "recording":
        assert time.monotonic() < deadline, "the size limit did not stop the recording"
        peer.publish("/rec/big", {"data": filler})
    ended = status(server, started["id"])
    assert ended["stop_reason"] == "max_size" and ended["size"] >= 0.02 * 1024 * 1024
    found = read_mcap_ros2(tmp_path / "rec" / f"{started['id']}.mcap")  # finished: summary and footer
    assert len(found["/rec/big"]) == ended["counts"]["/rec/big"] > 0


def test_no_start_below_the_free_disk_floor_or_over_the_folder_quota(app_factory, tmp_path):
    low = app_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "a"), ROVER_WEB_RECORDINGS_MIN_FREE_MB=1e8).test_client()
    answer = low.post("/api/recordings", json={"topics": "all"})
    assert answer.status_code == 507 and answer.json["error"] == "disk_low"
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "old.mcap").write_bytes(b"x" * 20000)
    full = app_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "b"), ROVER_WEB_RECORDINGS_MAX_MB=0.01).test_client()
    answer = full.post("/api/recordings", json={"topics": "all"})
    assert answer.status_code == 507 and answer.json["error"] == "folder_full"
    assert json.loads(full.get("/api/recordings").data)["recordings"] == []


def test_roles_viewers_list_operators_record_admins_delete(signed_server_factory, tmp_path):
    from tests.support.auth import bearer

    server = signed_server_factory(ROVER_WEB_RECORDINGS_DIR=str(tmp_path / "rec"))
    assert requests.get(server.url + "/api/recordings", headers=bearer(server, "viewer"), timeout=5).status_code == 200
    refused = requests.post(server.url + "/api/recordings", json={}, headers=bearer(server, "viewer"), timeout=5)
    assert refused.status_code == 403
    started = start(server, {"topics": "all"}, headers=bearer(server, "operator"))
    assert started["started_by"] == "operator"
    url = f"{server.url}/api/recordings/{started['id']}"
    stopped = requests.post(url + "/stop", json={}, headers=bearer(server, "operator"), timeout=15).json()
    assert stopped["stopped_by"] == "operator"
    assert requests.delete(url, headers=bearer(server, "operator"), timeout=5).status_code == 403
    assert requests.delete(url, headers=bearer(server, "admin"), timeout=5).status_code == 200


def test_a_subscription_rclpy_refuses_ends_the_recording_cleanly_and_says_why(app_factory, monkeypatch):
    app = app_factory()
    client = app.test_client()
    runtime = app.extensions["rover_web"].runtime
    wait_until(lambda: "/cmd_vel" in dict(runtime.node.get_topic_names_and_types()), 10, "own topics seen")

    def refuse(*args, **kwargs):
        raise RuntimeError("rmw said no")

    from rover_web.ros.raw_taker import RawTaker

    monkeypatch.setattr(RawTaker, "subscribe", refuse)
    answer = client.post("/api/recordings", json={"topics": "all"})
    assert answer.status_code == 503 and answer.json["error"] == "subscribe_failed"
    (listed,) = client.get("/api/recordings").json["recordings"]
    assert (listed["state"], listed["stop_reason"], listed["error"]) == ("stopped", "subscribe_failed",
                                                                         "RuntimeError: rmw said no")
    assert client.post("/api/recordings", json={"topics": "all"}).status_code == 503  # not stuck at 409
