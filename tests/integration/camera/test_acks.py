"""Pages that acknowledge the MJPEG bytes they receive (GET /stream?ack=1, POST
/api/camera/viewers/<id>/ack), over real TCP on 127.0.0.1 against the served app and a camera in
another process: the stream names itself and numbers its parts, acks move the server's counts,
bad or foreign acks are refused and change nothing, a page that stops acknowledging stops the
video after about a frame, and one that is silent too long has its stream ended.

Assertions are on bytes and frame counts; waits are for conditions (the machine is shared)."""

import pytest
import requests

from rover_web.camera import acks as acks_module
from rover_web.camera.rate import QUEUE_BUDGET_BYTES
from tests.integration.camera.test_stream import wait_listed
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros


def viewer(server, label, headers=None):
    reply = requests.get(server.url + "/api/camera/viewers", params={"viewer": label}, headers=headers,
                         timeout=5).json()
    return reply["viewers"][0] if reply["viewers"] else None


def ack(server, viewer_id, body, headers=None, **kwargs):
    return requests.post(f"{server.url}/api/camera/viewers/{viewer_id}/ack", json=body, headers=headers,
                         timeout=5, **kwargs)


def test_an_acked_stream_names_itself_numbers_its_parts_and_its_acks_count(live_server, image_publisher,
                                                                            mjpeg_client):
    topic = "/test_cam/acked"
    image_publisher(topic, width=160, height=120, hz=30)
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=acked&ack=1", ack=True)
    client.wait_frames(10, timeout=30)
    viewer_id = client.headers["x-camera-viewer"]
    assert len(viewer_id) >= 20
    seqs = [int(headers["x-frame-seq"]) for _, headers, _ in client.frames]
    assert seqs == list(range(1, len(seqs) + 1))
    assert all(int(headers["content-length"]) == len(data) for _, headers, data in client.frames)
    assert all(data[:2] == b"\xff\xd8" for _, _, data in client.frames)

    report = wait_until(lambda: (r := viewer(live_server, "acked")) and r["acked_bytes"] > 0 and r, 10,
                        "the page's acks counted")
    assert report["acked"] is True and report["adapt"] is True
    assert 0 < report["acked_bytes"] <= client.received
    assert client.acker.answers and set(client.acker.answers) == {204}
    wait_until(lambda: viewer(live_server, "acked")["acked_bytes"] >= client.acker.acked > report["acked_bytes"],
               10, "acks moving forward")

    # Without ack=1 nothing changes: no header, no numbers, no ack figures.
    plain = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=plain")
    plain.wait_frames(3, timeout=30)
    assert "x-camera-viewer" not in plain.headers
    assert all("x-frame-seq" not in headers for _, headers, _ in plain.frames)
    plain_report = viewer(live_server, "plain")
    assert plain_report["acked"] is False and "acked_bytes" not in plain_report

    client.close()
    wait_until(lambda: viewer(live_server, "acked") is None, 10, "the acked viewer's record removed")
    answer = ack(live_server, viewer_id, {"bytes": 1})
    assert answer.status_code == 404 and answer.json()["error"] == "unknown_viewer"


def test_bad_acks_get_a_clear_4xx_and_change_nothing(live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/bad_acks"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=bad&ack=1", ack=False)
    client.wait_frames(1, timeout=30)
    viewer_id = client.headers["x-camera-viewer"]
    good = ack(live_server, viewer_id, {"bytes": 100})
    assert good.status_code == 204 and good.content == b""
    before = viewer(live_server, "bad")
    assert before["acked_bytes"] == 100
    written = before["acked_bytes"] + before["unacked_bytes"]

    for body, code in (({}, "missing_field"), ({"bytes": "200"}, "bad_type"), ({"bytes": 200.5}, "bad_type"),
                       ({"bytes": True}, "bad_type"), ({"bytes": None}, "bad_type"), ({"bytes": -1}, "out_of_range"),
                       ({"bytes": written + 1}, "out_of_range"), ({"bytes": 10**30}, "out_of_range"),
                       ({"bytes": 200, "extra": 1}, "unknown_field"), ([200], "bad_json")):
        answer = ack(live_server, viewer_id, body)
        assert answer.status_code == 400 and answer.json()["error"] == code, (body, answer.text)
    for raw, code in (('{"bytes": NaN}', "non_finite"), ('{"bytes": 1e400}', "non_finite"), ("", "missing_body"),
                      ("{bytes: 1}", "bad_json")):
        answer = requests.post(f"{live_server.url}/api/camera/viewers/{viewer_id}/ack", data=raw, timeout=5,
                               headers={"Content-Type": "application/json"})
        assert answer.status_code == 400 and answer.json()["error"] == code, (raw, answer.text)
    not_json = requests.post(f"{live_server.url}/api/camera/viewers/{viewer_id}/ack", data="bytes=200", timeout=5,
                             headers={"Content-Type": "application/x-www-form-urlencoded"})
    assert not_json.status_code == 415
    foreign = ack(live_server, viewer_id, {"bytes": 200}, headers={"Origin": "http://elsewhere.example"})
    assert foreign.status_code == 403 and foreign.json()["error"] == "foreign_origin"
    for unknown in ("no-such-viewer", viewer_id[:-1] + ("A" if viewer_id[-1] != "A" else "B"), "x" * 300):
        answer = ack(live_server, unknown, {"bytes": 200})
        assert answer.status_code == 404 and answer.json()["error"] == "unknown_viewer"
    older = ack(live_server, viewer_id, {"bytes": 50})  # acks only move forward
    assert older.status_code == 204
    after = viewer(live_server, "bad")
    assert (after["acked_bytes"], after["acked_bytes"] + after["unacked_bytes"]) == (100, written)

    bad_query = requests.get(f"{live_server.url}/stream", params={"topic": topic, "ack": "yes"}, timeout=5)
    assert bad_query.status_code == 400 and bad_query.json()["error"] == "bad_value"


def test_an_ack_from_another_identity_is_404(signed_server, image_publisher, mjpeg_client):
    topic = "/test_cam/owned"
    image_publisher(topic, width=160, height=120, hz=30)
    token = {role: {"Authorization": f"Bearer {t}"} for role, t in signed_server.tokens.items()}
    wait_listed_signed(signed_server, topic, token["viewer"])
    client = mjpeg_client(f"{signed_server.url}/stream?topic={topic}&viewer=mine&ack=1", ack=False,
                          headers=token["viewer"])
    client.wait_frames(1, timeout=30)
    viewer_id = client.headers["x-camera-viewer"]
    for other in ("operator", "admin"):
        answer = ack(signed_server, viewer_id, {"bytes": 5}, headers=token[other])
        assert answer.status_code == 404 and answer.json()["error"] == "unknown_viewer"
    assert ack(signed_server, viewer_id, {"bytes": 5}).status_code == 401  # not signed in at all
    assert viewer(signed_server, "mine", token["viewer"])["acked_bytes"] == 0
    # The viewer role may acknowledge its own stream (acknowledging is watching, not commanding).
    assert ack(signed_server, viewer_id, {"bytes": 5}, headers=token["viewer"]).status_code == 204
    assert viewer(signed_server, "mine", token["viewer"])["acked_bytes"] == 5


def wait_listed_signed(server, topic, headers):
    def listed():
        topics = requests.get(server.url + "/api/topics", headers=headers, timeout=5).json()["topics"]
        return any(t["name"] == topic and t["publishers"] for t in topics)
    wait_until(listed, 15, f"{topic} listed")


def test_without_acks_the_stream_stops_after_about_a_frame_and_goes_on_when_acked(
        live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/unacked"
    camera = image_publisher(topic, width=320, height=240, hz=30, grain=30)  # ~21 kB frames
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=quiet&ack=1", ack=True, ack_paused=True)
    client.wait_frames(1, timeout=30)
    # Sixty more camera frames (two seconds at 30 Hz) while nothing is acknowledged.
    published = camera.status()["published"]
    wait_until(lambda: camera.status()["published"] >= published + 60, 30, "sixty more camera frames")
    report = viewer(live_server, "quiet")
    first_part = client.received
    # Everything the server wrote reached this client (loopback); it wrote the first frame and no
    # more than the queue budget beyond it: the unacknowledged bytes stay bounded.
    assert report["acked_bytes"] == 0
    assert report["unacked_bytes"] == client.received
    assert client.count <= 2 and report["unacked_bytes"] <= first_part + QUEUE_BUDGET_BYTES

    client.acker.sending = True  # the page acknowledges again: the video goes on
    client.acker.offer(client.received)
    client.wait_frames(client.count + 10, timeout=30)
    assert viewer(live_server, "quiet")["acked_bytes"] > first_part


def test_a_page_silent_too_long_has_its_stream_ended(live_server, image_publisher, mjpeg_client, monkeypatch):
    monkeypatch.setattr(acks_module, "ACK_STALL_S", 1.5)  # 30 s in service: the live server is this process
    topic = "/test_cam/silent"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=silent&ack=1", ack=False)
    client.wait_frames(1, timeout=30)
    viewer_id = client.headers["x-camera-viewer"]
    assert client.closed.wait(30), "the stream of a page that stopped acknowledging was not ended"
    wait_until(lambda: viewer(live_server, "silent") is None, 10, "its record removed")
    assert ack(live_server, viewer_id, {"bytes": 1}).status_code == 404
