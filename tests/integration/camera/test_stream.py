"""Camera streams against cameras in other processes: snapshot, shared MJPEG streams, one encode per
frame, subscriptions that exist only while someone watches, clean endings, refused input."""

import io
import threading
import time

import pytest
import requests
from PIL import Image

from rover_web.camera.service import CameraStreams
from tests.support.waiting import wait_until

IMAGE = "sensor_msgs/msg/Image"
COMPRESSED = "sensor_msgs/msg/CompressedImage"


def wait_listed(server, topic, timeout=15.0):
    """The app's node has discovered `topic` (needed for type auto-detection)."""
    def listed():
        topics = requests.get(server.url + "/api/topics", timeout=5).json()["topics"]
        return any(t["name"] == topic and t["publishers"] for t in topics)
    wait_until(listed, timeout, f"{topic} listed")


def streams(server):
    return server.rover.feature(CameraStreams)


def subscriber_count(peer, topic):
    return peer.graph(count_topics=[topic])["subscribers"][topic]


class Repeater:
    """Publishes a message from a ros_peer every 0.1 s in the background (cameras never stop)."""

    def __init__(self, peer, topic, msg):
        self.peer, self.topic, self.msg = peer, topic, msg
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        while not self.stop.is_set():
            self.peer.publish(self.topic, self.msg)
            self.stop.wait(0.1)

    def close(self):
        self.stop.set()
        self.thread.join(5)


def bgr_image(width, height, rgb, pad=4, sec=42):
    step = width * 3 + pad
    row = list(rgb[::-1]) * width + [7] * pad
    return {"header": {"frame_id": "cam", "stamp": {"sec": sec, "nanosec": 500000000}}, "width": width,
            "height": height, "encoding": "bgr8", "is_bigendian": 0, "step": step, "data": row * height}


def test_snapshot_returns_the_frame_published_by_another_process(live_server, ros_peer):
    peer = ros_peer("camera_peer")
    topic = "/test_cam/color"
    peer.advertise(topic, IMAGE)
    repeater = Repeater(peer, topic, bgr_image(16, 12, (200, 30, 60)))
    try:
        wait_listed(live_server, topic)
        response = requests.get(live_server.url + "/snapshot", params={"topic": topic}, timeout=10)
        assert response.status_code == 200 and response.headers["Content-Type"] == "image/jpeg"
        assert response.headers["X-Timestamp"] == "42.500000000"
        picture = Image.open(io.BytesIO(response.content)).convert("RGB")
        assert picture.size == (16, 12)
        assert all(abs(a - b) <= 14 for a, b in zip(picture.getpixel((8, 6)), (200, 30, 60), strict=True))
        scaled = requests.get(live_server.url + "/snapshot", params={"topic": topic, "width": 8}, timeout=10)
        assert Image.open(io.BytesIO(scaled.content)).size == (8, 6)
    finally:
        repeater.close()


def test_five_viewers_share_one_subscription_and_each_frame_is_encoded_once(
        live_server_factory, ros_peer, image_publisher, mjpeg_client):
    server = live_server_factory(ROVER_WEB_CAMERA_IDLE_TIMEOUT_S=0.5)
    topic = "/test_cam/shared"
    camera = image_publisher(topic, width=320, height=240, hz=30)
    wait_listed(server, topic)
    clients = [mjpeg_client(f"{server.url}/stream?topic={topic}") for _ in range(5)]
    for client in clients:
        client.wait_frames(30, timeout=30)
        assert client.status == 200 and client.headers["content-type"].startswith("multipart/x-mixed-replace")
    observer = ros_peer("graph_observer")
    # Five viewers, one ROS subscription (the app's); the camera sees exactly one subscriber.
    wait_until(lambda: subscriber_count(observer, topic) == 1, 10, "the app's subscription discovered")
    assert camera.status()["subscribers"] == 1
    [(key, producer, users)] = streams(server).producers.items()
    assert users == 5 and key.topic == topic and key.msg_type == IMAGE

    camera.close()  # no new frames: let every viewer receive the last one, then count
    time.sleep(1.0)
    stamps = [[float(headers["x-timestamp"]) for _, headers, _ in client.frames] for client in clients]
    for seen in stamps:
        assert seen == sorted(set(seen))  # in order, never the same frame twice
    delivered = set().union(*map(set, stamps))
    stats = producer.stats()
    assert producer.encodes == len(delivered)  # one encode per frame shown, whatever the number of viewers
    assert sorted(set(producer.encoded_seqs)) == sorted(producer.encoded_seqs)
    assert producer.encodes <= stats["received"]
    assert sum(map(len, stamps)) >= 3 * producer.encodes  # the frames were shared, not encoded per viewer
    assert Image.open(io.BytesIO(clients[0].frames[-1][2])).size == (320, 240)
    status = requests.get(server.url + "/api/camera/streams", timeout=5).json()
    assert status["viewers"] == 5 and status["streams"][0]["encodes"] == producer.encodes

    # The subscription disappears once the last viewer has left (after the configured linger).
    for client in clients[:4]:
        client.close()
    time.sleep(1.0)
    assert subscriber_count(observer, topic) == 1  # one viewer still watching
    clients[4].close()
    wait_until(lambda: subscriber_count(observer, topic) == 0, 10, "subscription removed from the graph")
    assert requests.get(server.url + "/api/camera/streams", timeout=5).json() == {"viewers": 0, "streams": []}


def test_a_browser_that_goes_away_releases_its_stream(live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/leaving"
    image_publisher(topic, width=160, height=120, hz=30)
    wait_listed(live_server, topic)
    camera = streams(live_server)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}")
    client.wait_frames(5)
    assert camera.viewers == 1
    client.close()  # while frames are flowing: the next write fails
    wait_until(lambda: camera.viewers == 0, 10, "viewer released after a failed write")
    # While no frame comes at all, the idle stream notices the closed socket by itself.
    idle = mjpeg_client(f"{live_server.url}/stream?topic=/test_cam/nobody&msg_type={IMAGE}")
    wait_until(lambda: idle.status == 200 and camera.viewers == 1, 10, "idle stream open")
    idle.close()
    wait_until(lambda: camera.viewers == 0, 10, "idle viewer released")


def test_a_best_effort_camera_is_heard_without_asking_for_its_qos(live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/best_effort"
    image_publisher(topic, width=160, height=120, hz=30, qos="sensor_data")
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}")
    client.wait_frames(5)  # a reliable subscription would hear nothing from a best-effort publisher
    [(key, _, _)] = streams(live_server).producers.items()
    assert key.qos == "sensor_data"


def test_shutdown_ends_open_streams(live_server, mjpeg_client):
    client = mjpeg_client(f"{live_server.url}/stream?topic=/test_cam/nobody&msg_type={IMAGE}")
    wait_until(lambda: client.status == 200, 10, "stream open")
    live_server.rover.shutdown()
    assert client.closed.wait(5), "the stream did not end on shutdown"


def test_unsupported_encoding_is_a_415_for_snapshots_and_an_error_frame_for_streams(
        live_server, ros_peer, mjpeg_client):
    peer = ros_peer("yuv_camera")
    topic = "/test_cam/yuv"
    peer.advertise(topic, IMAGE)
    msg = {"width": 4, "height": 2, "encoding": "yuv422", "step": 8, "data": [128] * 16}
    repeater = Repeater(peer, topic, msg)
    try:
        wait_listed(live_server, topic)
        response = requests.get(live_server.url + "/snapshot", params={"topic": topic}, timeout=10)
        assert response.status_code == 415
        assert response.json()["error"] == "unsupported_encoding" and "yuv422" in response.json()["message"]
        client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&width=320")
        client.wait_frames(1)
        picture = Image.open(io.BytesIO(client.frames[0][2]))
        assert picture.size == (320, 180)  # an image saying why, in the asked width
        described = requests.get(live_server.url + "/api/camera/streams", timeout=5).json()["streams"]
        [stream] = [s for s in described if s["width"] == 320]  # the snapshot's producer may still linger
        assert "yuv422" in stream["last_error"] and stream["errors"] >= 1
    finally:
        repeater.close()
    assert requests.get(live_server.url + "/api/status", timeout=5).json()["ros_ok"]


def test_compressed_jpeg_is_passed_through_and_png_is_converted(live_server, ros_peer):
    peer = ros_peer("compressed_camera")
    out = io.BytesIO()
    Image.new("RGB", (24, 16), (20, 180, 90)).save(out, "JPEG", quality=90)
    jpeg = out.getvalue()
    out = io.BytesIO()
    Image.new("RGB", (24, 16), (200, 30, 60)).save(out, "PNG")
    repeaters = []
    try:
        for topic, fmt, data in (("/test_cam/jpeg/compressed", "jpeg", jpeg),
                                 ("/test_cam/png/compressed", "png", out.getvalue())):
            peer.advertise(topic, COMPRESSED)
            repeaters.append(Repeater(peer, topic, {"format": fmt, "data": list(data)}))
        wait_listed(live_server, "/test_cam/jpeg/compressed")
        wait_listed(live_server, "/test_cam/png/compressed")
        same = requests.get(live_server.url + "/snapshot", params={"topic": "/test_cam/jpeg/compressed",
                                                                   "quality": 5}, timeout=10)
        assert same.status_code == 200 and same.content == jpeg  # not re-encoded, byte for byte
        converted = requests.get(live_server.url + "/snapshot", params={"topic": "/test_cam/png/compressed"},
                                 timeout=10)
        picture = Image.open(io.BytesIO(converted.content))
        assert picture.format == "JPEG" and picture.size == (24, 16)
        assert all(abs(a - b) <= 14 for a, b in zip(picture.convert("RGB").getpixel((12, 8)), (200, 30, 60),
                                                   strict=True))
        passthroughs = [s["passthroughs"] for s in streams(live_server).describe()
                        if s["topic"] == "/test_cam/jpeg/compressed"]
        assert passthroughs and passthroughs[0] >= 1
    finally:
        for repeater in repeaters:
            repeater.close()


@pytest.mark.parametrize("path, query, status, code", [
    ("/stream", {}, 400, "missing_field"),
    ("/stream", {"topic": "/bad//name"}, 400, "bad_topic"),
    ("/stream", {"topic": "/9cam"}, 400, "bad_topic"),
    ("/stream", {"topic": "/test_cam/none"}, 404, "unknown_topic"),
    ("/stream", {"topic": "/cmd_vel"}, 400, "not_an_image_topic"),  # the app's own Twist publisher
    ("/stream", {"topic": "/cmd_vel", "msg_type": IMAGE}, 400, "type_mismatch"),
    ("/stream", {"topic": "/x", "msg_type": "nonexistent_msgs/msg/Camera"}, 400, "unknown_type"),
    ("/stream", {"topic": "/x", "msg_type": "std_msgs/msg/String"}, 400, "not_an_image_type"),
    ("/stream", {"topic": "/x", "msg_type": "not a type"}, 400, "unknown_type"),
    ("/stream", {"topic": "/x", "width": "0.5"}, 400, "bad_type"),
    ("/stream", {"topic": "/x", "width": "100000"}, 400, "out_of_range"),
    ("/stream", {"topic": "/x", "height": "-3"}, 400, "out_of_range"),
    ("/stream", {"topic": "/x", "quality": "0"}, 400, "out_of_range"),
    ("/stream", {"topic": "/x", "quality": "1000"}, 400, "out_of_range"),
    ("/stream", {"topic": "/x", "qos_profile": "reliable"}, 400, "bad_value"),
    ("/stream", {"topic": "/x", "type": "h264"}, 400, "unsupported_stream_type"),
    ("/snapshot", {"topic": "/bad topic"}, 400, "bad_topic"),
    ("/snapshot", {"topic": "/x", "quality": "high"}, 400, "bad_type"),
])
def test_bad_requests_get_a_4xx_json_reason_and_subscribe_nothing(live_server, path, query, status, code):
    response = requests.get(live_server.url + path, params=query, timeout=10)
    assert response.status_code == status
    assert response.headers["Content-Type"] == "application/json"
    assert response.json()["error"] == code and response.json()["message"]
    assert len(streams(live_server).producers) == 0 and streams(live_server).viewers == 0


def test_snapshot_of_a_silent_topic_times_out_with_a_reason(live_server_factory):
    server = live_server_factory(ROVER_WEB_CAMERA_SNAPSHOT_TIMEOUT_S=0.3)
    response = requests.get(server.url + "/snapshot", params={"topic": "/test_cam/silent", "msg_type": IMAGE},
                            timeout=10)
    assert response.status_code == 504 and response.json()["error"] == "no_frame"
    assert streams(server).viewers == 0


def test_viewer_limit(live_server_factory, mjpeg_client):
    server = live_server_factory(ROVER_WEB_CAMERA_MAX_VIEWERS=1)
    first = mjpeg_client(f"{server.url}/stream?topic=/test_cam/nobody&msg_type={IMAGE}")
    wait_until(lambda: first.status == 200, 10, "first stream open")
    response = requests.get(server.url + "/stream", params={"topic": "/test_cam/nobody", "msg_type": IMAGE},
                            timeout=10)
    assert response.status_code == 503 and response.json()["error"] == "too_many_viewers"


def test_different_camera_streams_count_toward_a_cap_and_an_idle_one_makes_room(live_server_factory, mjpeg_client):
    """Every (topic, size, quality, QoS) is its own subscription and encoder: a query string must
    not make them without bound."""
    server = live_server_factory(ROVER_WEB_CAMERA_MAX_PRODUCERS=2, ROVER_WEB_CAMERA_IDLE_TIMEOUT_S=600)
    url = f"{server.url}/stream?topic=/test_cam/nobody&msg_type={IMAGE}&width="
    first = mjpeg_client(url + "100")
    second = mjpeg_client(url + "200")
    wait_until(lambda: first.status == 200 and second.status == 200, 10, "two streams open")
    refused = requests.get(url + "300", timeout=10)
    assert refused.status_code == 503 and refused.json()["error"] == "too_many_producers"
    assert len(streams(server).producers) == 2
    first.close()
    wait_until(lambda: streams(server).viewers == 1, 10, "first viewer released")
    third = mjpeg_client(url + "300")  # the idle 100-wide one goes now, not in 600 s
    wait_until(lambda: third.status == 200, 10, "third stream open")
    assert sorted(key.width for key, _, _ in streams(server).producers.items()) == [200, 300]


def test_an_asked_size_beyond_the_output_area_is_refused(live_server_factory):
    server = live_server_factory(ROVER_WEB_CAMERA_MAX_OUTPUT_PIXELS=1_000_000)
    response = requests.get(server.url + "/snapshot", timeout=10,
                            params={"topic": "/x", "msg_type": IMAGE, "width": "2000", "height": "1000"})
    assert response.status_code == 400 and response.json()["error"] == "out_of_range"
    assert "ROVER_WEB_CAMERA_MAX_OUTPUT_PIXELS" in response.json()["message"]
    assert len(streams(server).producers) == 0


def test_snapshot_requests_beyond_the_rate_get_429_with_retry_after(live_server_factory):
    server = live_server_factory(ROVER_WEB_CAMERA_SNAPSHOTS_PER_MIN=2, ROVER_WEB_CAMERA_SNAPSHOT_TIMEOUT_S=0.2)
    query = {"topic": "/test_cam/silent", "msg_type": IMAGE}
    for _ in range(2):
        assert requests.get(server.url + "/snapshot", params=query, timeout=10).status_code == 504
    refused = requests.get(server.url + "/snapshot", params=query, timeout=10)
    assert refused.status_code == 429 and refused.json()["error"] == "rate_limited"
    assert 1 <= int(refused.headers["Retry-After"]) <= 60
    assert len(streams(server).producers) == 0 or streams(server).viewers == 0
