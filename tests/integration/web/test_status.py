"""The app's node and other ROS processes: discovery, live data to SSE, status, isolation."""

import time

import requests

ODOM = "nav_msgs/msg/Odometry"


def odom(x: float, linear: float = 0.0) -> dict:
    return {"header": {"frame_id": "odom"}, "pose": {"pose": {"position": {"x": x}, "orientation": {"w": 1.0}}},
            "twist": {"twist": {"linear": {"x": linear}}}}


def warm_up_until_received(peer, rover, topic="/odom", timeout=10.0):
    """Discovery matches the two ends a moment apart; publish until the app has heard one."""
    deadline = time.monotonic() + timeout
    while not any(t["topic"] == topic and t["count"] for t in rover.runtime.topic_stats(2.0)):
        assert time.monotonic() < deadline, "the app never received the peer's message"
        peer.publish(topic, odom(-1.0))
        time.sleep(0.05)


def test_peer_message_reaches_sse_client_and_status(live_server, ros_peer, sse_client):
    peer = ros_peer()
    peer.advertise("/odom", ODOM)
    peer.wait_match("/odom")  # the app's subscription was discovered
    stream = sse_client(live_server.url + "/api/events?channels=status,odom")
    warm_up_until_received(peer, live_server.rover)
    baseline = next(t for t in live_server.rover.runtime.topic_stats(2.0) if t["topic"] == "/odom")["count"]
    started = time.monotonic()
    for i in range(30):
        peer.publish("/odom", odom(x=i * 0.1, linear=0.5))
        time.sleep(max(0.0, started + (i + 1) * 0.05 - time.monotonic()))  # 20 Hz
    time.sleep(0.05)
    status = requests.get(live_server.url + "/api/status", timeout=5).json()
    # The last value always arrives, even though the channel is throttled for browsers.
    event = stream.wait_for("odom", lambda d: d["x"] == 2.9 and d["linear"] == 0.5)
    assert event["json"]["frame_id"] == "odom"
    topic = next(t for t in status["topics"] if t["topic"] == "/odom")
    assert topic["type"] == ODOM and topic["count"] == baseline + 30 and topic["fresh"]
    assert topic["age_s"] < 1.0
    assert 17 <= topic["rate_hz"] <= 23
    assert status["robot_link"] == "ok"
    assert status["middleware"].startswith("rmw_")
    assert status["node"] == "/rover_web"
    # The status channel carries the same picture for the pages.
    stream.wait_for("status", lambda s: s["robot_link"] == "ok")


def test_status_goes_stale_when_the_robot_falls_silent(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_STALE_AFTER_S=0.3)
    peer = ros_peer()
    peer.advertise("/odom", ODOM)
    peer.wait_match("/odom")
    peer.publish("/odom", odom(0.0))
    deadline = time.monotonic() + 5
    while requests.get(server.url + "/api/status", timeout=5).json()["robot_link"] != "ok":
        assert time.monotonic() < deadline
        time.sleep(0.02)
    time.sleep(0.5)
    status = requests.get(server.url + "/api/status", timeout=5).json()
    assert status["robot_link"] == "stale"
    assert next(t for t in status["topics"] if t["topic"] == "/odom")["fresh"] is False


def test_two_apps_in_one_process_do_not_share_ros_state(app_factory, ros_peer):
    a = app_factory(ROVER_WEB_NODE_NAME="app_a", ROVER_WEB_ODOM_TOPIC="/a/odom")
    b = app_factory(ROVER_WEB_NODE_NAME="app_b", ROVER_WEB_ODOM_TOPIC="/b/odom")
    ra, rb = a.extensions["rover_web"], b.extensions["rover_web"]
    assert ra.runtime.context is not rb.runtime.context
    peer = ros_peer()
    peer.advertise("/a/odom", ODOM)
    peer.wait_match("/a/odom")
    peer.publish("/a/odom", odom(1.0))
    deadline = time.monotonic() + 5
    while ra.hub.latest("odom") is None:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    assert rb.hub.latest("odom") is None
    assert a.test_client().get("/api/status").json["node"] == "/app_a"
    assert b.test_client().get("/api/status").json["node"] == "/app_b"
    # Shutting one down leaves the other running.
    ra.shutdown()
    assert rb.runtime.running
    peer.advertise("/b/odom", ODOM)
    peer.wait_match("/b/odom")
    deadline = time.monotonic() + 10
    while rb.hub.latest("odom") is None:  # b still hears its own topic after a is gone
        assert time.monotonic() < deadline
        peer.publish("/b/odom", odom(2.0))
        time.sleep(0.05)
    deadline = time.monotonic() + 10
    while "/app_b" not in (nodes := peer.graph()["nodes"]):  # graph discovery lags data
        assert time.monotonic() < deadline, nodes
        time.sleep(0.1)


def test_telemetry_and_the_gps_heading_share_one_odom_subscription(live_server, ros_peer, sse_client):
    """Both read /odom by default: one subscription takes each message once and serves both, and
    it is taken off the executor (its thread of its own), on the app's one node."""
    node = live_server.rover.runtime.node
    assert "/odom" not in [s.topic_name for s in node.subscriptions]
    peer = ros_peer()
    peer.advertise("/odom", ODOM)
    peer.wait_match("/odom")
    assert peer.graph(["/odom"])["subscribers"]["/odom"] == 1  # the whole graph: our one, and no other
    assert [n for n, _ns in node.get_subscriber_names_and_types_by_node(node.get_name(), "/")
            if n == "/odom"] == ["/odom"]
    stream = sse_client(live_server.url + "/api/events?channels=odom,heading")
    warm_up_until_received(peer, live_server.rover)
    facing_north = odom(x=4.0)  # yaw +90 degrees (ENU): a compass bearing of 0
    facing_north["pose"]["pose"]["orientation"] = {"z": 0.7071067811865476, "w": 0.7071067811865476}
    peer.publish("/odom", facing_north)
    stream.wait_for("odom", lambda d: d["x"] == 4.0 and abs(d["yaw"] - 1.5708) < 1e-3)
    heading = stream.wait_for("heading", lambda d: abs(d["yaw_rad"] - 1.570796) < 1e-5)
    assert heading["json"]["heading_deg"] in (0.0, 360.0) and heading["json"]["topic"] == "/odom"
