"""The topic browser against other processes: listing, echo of any type, measured rate and bandwidth,
subscriptions removed when nobody looks, refused input."""

import time

import pytest
import requests

from rover_web.topics.service import TopicBrowser
from tests.support.camera_peer import ImagePublisher
from tests.support.waiting import wait_until

TWIST = "geometry_msgs/msg/Twist"


def topic_entry(server, name):
    topics = requests.get(server.url + "/api/topics", timeout=5).json()["topics"]
    return next((t for t in topics if t["name"] == name), None)


def echoes(server):
    return server.rover.feature(TopicBrowser).echoes


def test_a_topic_of_another_process_is_listed_with_its_type_live(live_server, ros_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=topics")
    peer = ros_peer("chatter_peer")
    peer.advertise("/test/chatter", "std_msgs/msg/String")
    # Endpoints can be discovered a moment before the name of their node.
    entry = wait_until(lambda: (e := topic_entry(live_server, "/test/chatter")) and "(node" not in str(e) and e,
                       15, "topic listed")
    assert entry["types"] == ["std_msgs/msg/String"]
    assert entry["publishers"] == 1 and entry["publisher_nodes"] == ["/chatter_peer"] and entry["subscribers"] == 0
    # The `topics` channel brings the same list to open pages without a reload.
    event = stream.wait_for("topics", lambda d: any(t["name"] == "/test/chatter" for t in d["topics"]), timeout=10)
    assert event["json"]["node"] == "/rover_web"
    # And the app's own endpoints are there too, as `ros2 topic info` counts them.
    assert "/rover_web" in topic_entry(live_server, "/cmd_vel")["publisher_nodes"]
    # The page itself renders with the list in it.
    page = requests.get(live_server.url + "/topics", timeout=5).text
    assert "/test/chatter" in page and "std_msgs/msg/String" in page


def test_echo_shows_the_fields_of_any_message_type(live_server, ros_peer, sse_client):
    peer = ros_peer("twist_peer")
    peer.advertise("/test/twist", TWIST)
    wait_until(lambda: topic_entry(live_server, "/test/twist"), 15, "topic listed")
    stream = sse_client(live_server.url + "/api/topics/echo?topic=/test/twist")
    first = stream.wait_for("stats", timeout=10)["json"]
    assert first["type"] == TWIST and first["qos"] == "reliable, volatile"
    deadline = time.monotonic() + 15
    while not [e for e in stream.of("echo") if e["json"]["msg"]]:
        assert time.monotonic() < deadline, "no echo arrived"
        peer.publish("/test/twist", {"linear": {"x": 1.5}, "angular": {"z": -0.25}})
        time.sleep(0.1)
    msg = stream.of("echo")[-1]["json"]["msg"]
    assert msg == {"linear": {"x": 1.5, "y": 0.0, "z": 0.0}, "angular": {"x": 0.0, "y": 0.0, "z": -0.25}}


def test_echo_truncates_long_arrays_and_shows_their_length(live_server, ros_peer, sse_client):
    peer = ros_peer("array_peer")
    peer.advertise("/test/floats", "std_msgs/msg/Float32MultiArray")
    wait_until(lambda: topic_entry(live_server, "/test/floats"), 15, "topic listed")
    stream = sse_client(live_server.url + "/api/topics/echo?topic=/test/floats")
    stream.wait_for("stats", timeout=10)
    deadline = time.monotonic() + 15
    while not stream.of("echo"):
        assert time.monotonic() < deadline, "no echo arrived"
        peer.publish("/test/floats", {"data": [float(i) for i in range(100)]})
        time.sleep(0.1)
    data = stream.of("echo")[-1]["json"]["msg"]["data"]
    assert data["truncated"] is True and data["length"] == 100 and data["head"] == [float(i) for i in range(32)]


def test_rate_and_bandwidth_are_measured_within_10_percent_and_the_subscription_goes_away(
        live_server_factory, ros_peer, sse_client):
    server = live_server_factory(ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S=0.3, ROVER_WEB_TOPICS_ECHO_HZ=2.0)
    topic = "/test/rated"
    camera = ImagePublisher(topic, width=64, height=48, hz=20)
    try:
        wait_until(lambda: topic_entry(server, topic), 15, "topic listed")
        stream = sse_client(server.url + f"/api/topics/echo?topic={topic}")
        stream.wait_for("echo", timeout=15)
        time.sleep(1.0)
        start = camera.status()
        time.sleep(6.0)  # longer than the 5 s measuring window
        end = camera.status()
        true_rate = (end["published"] - start["published"]) / (end["t"] - start["t"])
        time.sleep(1.2)  # a stats event goes out every second
        last = [e for e in stream.events if e["t"] >= end["t"]][-1]["json"]["stats"]
        assert true_rate == pytest.approx(20.0, rel=0.25)  # the publisher itself ran about right
        assert last["rate_hz"] == pytest.approx(true_rate, rel=0.10)
        # Serialized size: 64×48×3 bytes of pixels plus the header, encoding and CDR framing.
        assert 64 * 48 * 3 < last["size_bytes"] < 64 * 48 * 3 + 100
        assert last["bandwidth_bps"] == pytest.approx(last["rate_hz"] * last["size_bytes"], rel=0.02)
        # 20 messages a second arrive, 2 a second are decoded and shown.
        shown = [e for e in stream.of("echo") if e["t"] >= start["t"] and e["t"] <= end["t"]]
        assert 6 <= len(shown) <= 14
        [(_, echo, users)] = echoes(server).items()
        assert users == 1 and echo.decodes <= echo.meter.count // 5
        observer = ros_peer("echo_observer")
        wait_until(lambda: observer.graph(count_topics=[topic])["subscribers"][topic] == 1, 10, "echo discovered")
        stream.close()  # the browser leaves: the echo subscription is removed
        wait_until(lambda: observer.graph(count_topics=[topic])["subscribers"][topic] == 0, 10,
                   "echo subscription removed")
        assert len(echoes(server)) == 0
    finally:
        camera.close()


def test_viewers_of_one_topic_share_one_subscription(live_server, ros_peer, sse_client):
    peer = ros_peer("shared_peer")
    peer.advertise("/test/shared", TWIST)
    wait_until(lambda: topic_entry(live_server, "/test/shared"), 15, "topic listed")
    streams = [sse_client(live_server.url + "/api/topics/echo?topic=/test/shared") for _ in range(3)]
    for stream in streams:
        stream.wait_for("stats", timeout=10)
    [(key, _, users)] = echoes(live_server).items()
    assert key == ("/test/shared", TWIST) and users == 3
    wait_until(lambda: peer.graph(count_topics=["/test/shared"])["subscribers"]["/test/shared"] == 1, 10,
               "one subscription for three viewers")


@pytest.mark.parametrize("query, status, code", [
    ({}, 400, "missing_field"),
    ({"topic": "/a//b"}, 400, "bad_topic"),
    ({"topic": "/test/none"}, 404, "unknown_topic"),
    ({"topic": "/test/none", "type": "nonexistent_msgs/msg/Thing"}, 422, "unknown_type"),
    ({"topic": "/test/none", "type": "std_msgs/msg/NoSuchMessage"}, 422, "unknown_type"),
    ({"topic": "/test/none", "type": "not-a-type"}, 422, "unknown_type"),
    ({"topic": "/cmd_vel", "type": "std_msgs/msg/String"}, 400, "type_mismatch"),
])
def test_bad_echo_requests_get_a_4xx_json_reason(live_server, query, status, code):
    response = requests.get(live_server.url + "/api/topics/echo", params=query, timeout=10)
    assert response.status_code == status and response.headers["Content-Type"] == "application/json"
    assert response.json()["error"] == code and response.json()["message"]
    assert len(echoes(live_server)) == 0


def test_echo_of_a_topic_not_yet_published_waits_for_it_with_a_type(live_server, sse_client):
    stream = sse_client(live_server.url + "/api/topics/echo?topic=/test/later&type=std_msgs/String")
    assert stream.wait_for("stats", timeout=10)["json"]["type"] == "std_msgs/msg/String"


@pytest.mark.parametrize("param,path", [("type", "/api/topics/echo?topic=/x&type={}"),
                                        ("msg_type", "/snapshot?topic=/x&msg_type={}")])
def test_a_type_name_from_the_query_never_imports_a_python_module(client, param, path):
    """type=this/msg/X used to import Python's `this` (and antigravity/msg/X to start a browser)."""
    import sys

    assert "this" not in sys.modules
    response = client.get(path.format("this/msg/X"))
    assert 400 <= response.status_code < 500, (param, response.status_code, response.get_data(as_text=True))
    assert response.is_json and "interface package" in response.get_json()["message"]
    assert "this" not in sys.modules


@pytest.mark.parametrize("topic", ["/a%0A/b", "/chatter%0A"])
def test_a_topic_name_with_a_line_break_is_a_400_not_a_500(client, topic):
    response = client.get(f"/api/topics/echo?topic={topic}&type=std_msgs/msg/String")
    assert response.status_code == 400, response.get_data(as_text=True)
    assert response.get_json()["error"] == "bad_topic"


def test_different_echoes_count_toward_a_cap_and_an_idle_one_makes_room_at_once(live_server_factory, sse_client):
    """Each echo query makes a ROS subscription: a client asking for many topics must not make
    unbounded subscriptions. Beyond the cap a 503; an idle one (lingering) goes at once for a new one."""
    server = live_server_factory(ROVER_WEB_TOPICS_ECHO_MAX_SUBSCRIPTIONS=2, ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S=600)
    url = server.url + "/api/topics/echo?type=std_msgs/msg/String&topic="
    first = sse_client(url + "/test/cap_a")
    sse_client(url + "/test/cap_b").wait_for("stats", timeout=10)
    first.wait_for("stats", timeout=10)
    refused = requests.get(url + "/test/cap_c", timeout=5)
    assert refused.status_code == 503 and refused.json()["error"] == "too_many_subscriptions"
    assert len(echoes(server)) == 2
    again = sse_client(url + "/test/cap_a")  # sharing an open one is never refused
    again.wait_for("stats", timeout=10)
    assert len(echoes(server)) == 2
    key_a = ("/test/cap_a", "std_msgs/msg/String")
    first.close()
    wait_until(lambda: echoes(server).users(key_a) == 1, 10, "first viewer left")
    assert requests.get(url + "/test/cap_c", timeout=5).status_code == 503  # both still watched
    again.close()
    wait_until(lambda: echoes(server).users(key_a) == 0, 10, "last viewer of /test/cap_a left")
    # Lingering for 600 s, yet it makes room at once: a lingering one only saves a re-subscription.
    sse_client(url + "/test/cap_c").wait_for("stats", timeout=10)
    assert key_a not in echoes(server) and len(echoes(server)) == 2
