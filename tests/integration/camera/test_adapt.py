"""MJPEG that fits the link, over real TCP on 127.0.0.1 against the served app and a camera in another
process: a viewer behind a slow link gets fewer and smaller frames while a fast viewer of the same
topic keeps the full rate, the server's socket never piles up video, the caps hold, and with
ROVER_WEB_CAMERA_ADAPT=false everything is as before (and the queue does pile up: the check can fail).

Rates here are generous bounds over windows of seconds, not timings: the machine is shared."""

import statistics
import threading
import time

import pytest
import requests

from rover_web.camera.rate import FPS_FLOOR
from rover_web.camera.service import CameraStreams
from tests.integration.camera.test_stream import wait_listed
from tests.integration.camera.throttle import Throttle, server_queue
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

SLOW_BPS = 40_000  # 320 kbit/s: a radio link; a 320×240 quality-80 frame with grain is ~21 kB


@pytest.fixture
def throttle():
    made = []

    def make(port, bytes_per_s, **kwargs):
        proxy = Throttle(port, bytes_per_s, **kwargs)
        made.append(proxy)
        return proxy

    yield make
    for proxy in made:
        proxy.close()


def viewers(server, label=None):
    params = {"viewer": label} if label else {}
    return requests.get(server.url + "/api/camera/viewers", params=params, timeout=5).json()


def window(client, seconds):
    """Frames and bytes `client` receives over the next `seconds`: (fps, bytes/s, mean frame bytes)."""
    count0, bytes0, t0 = client.count, client.bytes, time.monotonic()
    time.sleep(seconds)
    frames, nbytes, dt = client.count - count0, client.bytes - bytes0, time.monotonic() - t0
    return frames / dt, nbytes / dt, nbytes / max(1, frames)


def sample_targets(server, label, seconds):
    """The viewer's target rate (kbit/s) every 0.2 s over `seconds`, None readings left out."""
    deadline, seen = time.monotonic() + seconds, []
    while time.monotonic() < deadline:
        [viewer] = viewers(server, label)["viewers"]
        if viewer["target_kbps"] is not None:
            seen.append(viewer["target_kbps"])
        time.sleep(0.2)
    return seen


def watch_queue(server, proxy, seconds):
    """The largest server-side send queue of the proxied connection over `seconds` (/proc/net/tcp)."""
    deadline, most = time.monotonic() + seconds, 0
    while time.monotonic() < deadline:
        most = max(most, server_queue(server.port, proxy.upstream_port) or 0)
        time.sleep(0.02)
    return most


def test_a_slow_viewer_gets_fewer_smaller_frames_and_a_fast_one_keeps_full_rate(
        live_server, image_publisher, mjpeg_client, throttle):
    topic = "/test_cam/adapt"
    camera = image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(live_server, topic)
    fast = mjpeg_client(f"{live_server.url}/stream?topic={topic}&viewer=fast")
    fast.wait_frames(10, timeout=30)
    proxy = throttle(live_server.port, SLOW_BPS)
    slow = mjpeg_client(f"{proxy.url}/stream?topic={topic}&viewer=slow")
    slow.wait_frames(3, timeout=30)

    def slow_step():
        [viewer] = viewers(live_server, "slow")["viewers"]
        return viewer["step"]

    wait_until(lambda: slow_step() >= 1, 40, "the slow viewer's quality lowered")
    time.sleep(3)  # settle
    most_queued, targets = [], []
    watcher = threading.Thread(target=lambda: most_queued.append(watch_queue(live_server, proxy, 6)))
    sampler = threading.Thread(target=lambda: targets.extend(sample_targets(live_server, "slow", 6)))
    watcher.start()
    sampler.start()
    slow_fps, slow_bps, slow_frame = window(slow, 6)
    fast_fps, fast_bps, fast_frame = window(fast, 2)
    watcher.join()
    sampler.join()

    assert fast_fps > 15  # a 30 Hz camera; the fast viewer is not held back by the slow one
    # Quality and size went down so that frames keep coming (the floor is FPS_FLOOR a second).
    assert 2 < slow_fps <= 1.1 * fast_fps
    assert slow_frame < 0.5 * fast_frame
    assert slow_bps < 1.5 * SLOW_BPS
    # Never more than about a frame in the server's socket (a 21 kB frame plus the 16 kB budget):
    # without adaptation it is megabytes (test below).
    assert most_queued[0] < 64_000, most_queued
    [slow_report] = viewers(live_server, "slow")["viewers"]
    [fast_report] = viewers(live_server, "fast")["viewers"]
    assert fast_report["step"] == 0 and fast_report["quality"] == 80
    assert (fast_report["width"], fast_report["height"]) == (320, 240)
    # The target tracks the link: it probes above it now and then (CI once read 758 kbit/s on this
    # 320 kbit/s link, between two frames that pushed it back down), so its median over the window
    # is what is held to the link; it may read None while a fresh estimate is made. Twice the link:
    # a loaded CI machine read a median of 1.6 x once, while what the viewer got (slow_bps above)
    # stayed under 1.5 x; a target that did not track the link would read the fast viewer's ~10 x.
    assert slow_report["quality"] < 80
    assert targets and statistics.median(targets) < 8 * SLOW_BPS * 2 / 1000, targets
    assert fast_report["fps"] > 15 and 0 < slow_report["kbps"] < 8 * SLOW_BPS * 1.5 / 1000
    # Outputs are shared producers of one ROS subscription: the camera sees a single subscriber.
    producers = live_server.rover.feature(CameraStreams).producers.items()
    assert len(producers) >= 2 and {key.topic for key, _, _ in producers} == {topic}
    assert camera.status()["subscribers"] == 1


def test_the_slow_viewer_recovers_when_its_link_does(live_server, image_publisher, mjpeg_client, throttle):
    topic = "/test_cam/recover"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(live_server, topic)
    proxy = throttle(live_server.port, SLOW_BPS)
    slow = mjpeg_client(f"{proxy.url}/stream?topic={topic}&viewer=v")
    slow.wait_frames(3, timeout=30)

    def report():
        return viewers(live_server, "v")["viewers"][0]

    wait_until(lambda: report()["step"] >= 1, 40, "quality lowered on the slow link")
    proxy.bytes_per_s = 50_000_000  # the link recovers
    wait_until(lambda: report()["step"] == 0, 90, "back to the asked quality and size")
    assert report()["quality"] == 80 and (report()["width"], report()["height"]) == (320, 240)


def test_without_adaptation_the_slow_viewer_gets_every_frame_as_asked_and_the_queue_piles_up(
        live_server_factory, image_publisher, mjpeg_client, throttle):
    server = live_server_factory(ROVER_WEB_CAMERA_ADAPT=False)
    topic = "/test_cam/plain"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(server, topic)
    proxy = throttle(server.port, SLOW_BPS)
    slow = mjpeg_client(f"{proxy.url}/stream?topic={topic}&viewer=slow")
    slow.wait_frames(3, timeout=30)
    # Today's behaviour: the server writes as fast as the camera makes frames, the socket takes
    # them all, and the video queued in front of anything else grows far beyond a frame.
    wait_until(lambda: (server_queue(server.port, proxy.upstream_port) or 0) > 256_000, 30,
               "video piling up in the server's socket")
    sizes = {len(data) for _, _, data in slow.frames}
    assert min(sizes) > 15_000  # every frame at quality 80, full size
    [report] = viewers(server, "slow")["viewers"]
    assert report["adapt"] is False and report["quality"] == 80 and report["width"] == 320


def test_the_per_viewer_cap_holds_on_a_fast_link(live_server_factory, image_publisher, mjpeg_client):
    cap_kbps = 400  # 50 kB/s
    server = live_server_factory(ROVER_WEB_CAMERA_VIEWER_MAX_KBPS=cap_kbps)
    topic = "/test_cam/capped"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(server, topic)
    client = mjpeg_client(f"{server.url}/stream?topic={topic}")
    client.wait_frames(5, timeout=30)
    time.sleep(4)  # settle
    fps, bps, _ = window(client, 6)
    assert bps < cap_kbps * 1000 / 8 * 1.3
    assert fps > FPS_FLOOR / 3  # quality and size went down to keep frames coming


def test_the_total_budget_is_shared_by_the_viewers(live_server_factory, image_publisher, mjpeg_client):
    total_kbps = 800  # 100 kB/s for everyone
    server = live_server_factory(ROVER_WEB_CAMERA_TOTAL_MAX_KBPS=total_kbps)
    topic = "/test_cam/budget"
    image_publisher(topic, width=320, height=240, hz=30, grain=30)
    wait_listed(server, topic)
    clients = [mjpeg_client(f"{server.url}/stream?topic={topic}") for _ in range(3)]
    for client in clients:
        client.wait_frames(5, timeout=30)
    time.sleep(4)
    counts0, bytes0, t0 = [c.count for c in clients], [c.bytes for c in clients], time.monotonic()
    time.sleep(6)
    dt = time.monotonic() - t0
    rates = [(c.bytes - b) / dt for c, b in zip(clients, bytes0, strict=True)]
    assert sum(rates) < total_kbps * 1000 / 8 * 1.3
    assert all(c.count - n > 6 for c, n in zip(clients, counts0, strict=True))  # nobody starved
    assert max(rates) < 2.5 * min(rates)


def test_the_viewers_report_names_each_stream_and_refuses_a_bad_label(live_server, image_publisher, mjpeg_client):
    topic = "/test_cam/report"
    image_publisher(topic, width=160, height=120, hz=30)
    wait_listed(live_server, topic)
    client = mjpeg_client(f"{live_server.url}/stream?topic={topic}&width=80&viewer=card-1")
    client.wait_frames(10, timeout=30)
    wait_until(lambda: viewers(live_server, "card-1")["viewers"][0]["fps"] > 5, 10, "fps measured")
    body = viewers(live_server, "card-1")
    [report] = body["viewers"]
    assert body["adapt"] is True
    assert report["topic"] == topic and report["viewer"] == "card-1"
    assert (report["width"], report["height"]) == (80, 60) and report["kbps"] > 0
    assert report["asked"] == {"width": 80, "height": None, "quality": 80}
    assert viewers(live_server, "someone-else")["viewers"] == []
    for path, query in (("/api/camera/viewers", {"viewer": "bad label!"}),
                        ("/stream", {"topic": topic, "viewer": "x" * 65})):
        response = requests.get(live_server.url + path, params=query, timeout=5)
        assert response.status_code == 400 and response.json()["error"] == "bad_value"
    client.close()
    wait_until(lambda: viewers(live_server)["viewers"] == [], 10, "the viewer's record removed")
