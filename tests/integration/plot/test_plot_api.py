"""Plots against a real publisher: GET /api/plot and the `plot` channel carry a field's numbers, NaN is
skipped, arrays by index, the topic browser's subscription is shared and ends when nobody plots, bad fields are 400."""

import math

import pytest
import requests

from rover_web.plot.service import Plots
from rover_web.topics.service import TopicBrowser
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

ODOM = "nav_msgs/msg/Odometry"


def plot(server, **params):
    return requests.get(server.url + "/api/plot", params=params, timeout=5)


def listed(server, topic):
    return any(t["name"] == topic for t in requests.get(server.url + "/api/topics", timeout=5).json()["topics"])


def test_a_field_is_plotted_from_another_process(live_server_factory, ros_peer, sse_client):
    server = live_server_factory(ROVER_WEB_PLOT_IDLE_S=1.0, ROVER_WEB_TOPICS_ECHO_IDLE_TIMEOUT_S=0.2)
    peer = ros_peer("odom_peer")
    peer.advertise("/test/odom", ODOM)
    wait_until(lambda: listed(server, "/test/odom"), 15, "topic listed")
    stream = sse_client(server.url + "/api/events?channels=plot")
    first = plot(server, topic="/test/odom", field="twist.twist.linear.x", seconds=60)
    assert first.status_code == 200 and first.json()["t"] == []
    assert first.json()["id"] == "/test/odom twist.twist.linear.x"
    key = ("/test/odom", ODOM)
    echoes = server.rover.feature(TopicBrowser).echoes
    assert key in echoes and echoes.users(key) == 1  # the topic browser's own shared subscription
    peer.wait_match("/test/odom")
    field = "twist.twist.linear.x"
    # In batches of five: the subscription keeps the last 10 (as `ros2 topic echo` does), and a
    # loaded machine's executor may take a burst of 21 after some were overwritten.
    for i in range(20):
        peer.publish("/test/odom", {"twist": {"twist": {"linear": {"x": float(i)}}}})
        if i == 10:
            peer.publish("/test/odom", {"twist": {"twist": {"linear": {"x": math.nan}}}})
        if i % 5 == 4:
            reply = wait_until(lambda n=i + 1: len((r := plot(server, topic="/test/odom", field=field)).json()["v"])
                               == n and r, 10, f"{i + 1} points")
    assert "NaN" not in reply.text
    body = reply.json()
    assert body["v"] == [float(i) for i in range(20)] and body["skipped_nonfinite"] == 1
    assert body["t"] == sorted(body["t"]) and not body["decimated"]
    # The channel carried the same points, in order.
    wait_until(lambda: sum(len(e["json"]["series"].get(body["id"], {}).get("v", [])) for e in stream.of("plot")) == 20,
               5, "20 points on the channel")
    sent = [v for e in stream.of("plot") for v in e["json"]["series"][body["id"]]["v"]]
    assert sent == [float(i) for i in range(20)]
    # A second field of the same topic shares the one subscription.
    assert plot(server, topic="/test/odom", field="pose.pose.position.y").status_code == 200
    assert len(echoes) == 1 and echoes.users(key) == 1
    # Nobody asks any more: the series end and the subscription goes.
    wait_until(lambda: key not in echoes, 10, "subscription released")
    assert server.rover.feature(Plots).active() == []


def test_array_elements_by_index_and_short_arrays_skipped(live_server, ros_peer):
    peer = ros_peer("joint_peer")
    peer.advertise("/test/joints", "sensor_msgs/msg/JointState")
    wait_until(lambda: listed(live_server, "/test/joints"), 15, "topic listed")
    assert plot(live_server, topic="/test/joints", field="position[2]").status_code == 200
    peer.wait_match("/test/joints")
    peer.publish("/test/joints", {"position": [1.0, 2.0, 3.5]})
    peer.publish("/test/joints", {"position": [1.0]})
    peer.publish("/test/joints", {"position": [0.0, 0.0, -7.25]})
    body = wait_until(lambda: len((b := plot(live_server, topic="/test/joints", field="position[2]").json())["v"]) == 2
                      and b, 10, "two points")
    assert body["v"] == [3.5, -7.25] and body["skipped_nonfinite"] == 1
    fields = requests.get(live_server.url + "/api/plot/fields", params={"topic": "/test/joints"}, timeout=5).json()
    assert "position[0]" in fields["fields"] and "header.stamp.sec" in fields["fields"]


@pytest.mark.parametrize("params,status,code", [
    ({"field": "header.frame_id"}, 400, "not_numeric"),
    ({"field": "twist.twist.linear"}, 400, "not_numeric"),
    ({"field": "twist.twist.linear.w"}, 400, "no_such_field"),
    ({"field": "pose.covariance[36]"}, 400, "no_such_field"),
    ({"field": "twist..x"}, 400, "bad_field"),
    ({"field": ""}, 400, "bad_field"),
    ({"field": "twist.twist.linear.x", "seconds": "nan"}, 400, "bad_seconds"),
    ({"field": "twist.twist.linear.x", "seconds": "-1"}, 400, "bad_seconds"),
    ({"field": "twist.twist.linear.x", "topic": "/nobody/publishes/this"}, 404, "unknown_topic"),
    ({"field": "twist.twist.linear.x", "topic": "not a topic"}, 400, None),
])
def test_bad_requests_are_refused_with_json(live_server, params, status, code):
    query = {"topic": "/odom", "type": ODOM, **params}
    if "topic" in params and params["topic"].startswith("/nobody"):
        query.pop("type")
    reply = plot(live_server, **query)
    assert reply.status_code == status and reply.json()["message"]
    if code:
        assert reply.json()["error"] == code
    assert live_server.rover.feature(Plots).active() == []  # nothing started


def test_plots_and_echoes_share_one_subscription_and_the_topic_browsers_cap(live_server_factory, ros_peer,
                                                                            sse_client):
    server = live_server_factory(ROVER_WEB_SSE_MAX_CLIENTS=2)  # also the topic browser's viewer cap
    peer = ros_peer("shared_peer")
    peer.advertise("/test/shared", ODOM)
    peer.advertise("/test/other", ODOM)
    wait_until(lambda: listed(server, "/test/shared") and listed(server, "/test/other"), 15, "topics listed")
    assert plot(server, topic="/test/shared", field="twist.twist.linear.x").status_code == 200
    echo = sse_client(server.url + "/api/topics/echo?topic=/test/shared")
    echo.wait_for("stats", timeout=10)
    echoes = server.rover.feature(TopicBrowser).echoes
    key = ("/test/shared", ODOM)
    assert len(echoes) == 1 and echoes.users(key) == 2  # the echo viewer and the plot: one subscription
    # The plot counts as one of the topic browser's viewers: the cap of two is reached.
    refused = plot(server, topic="/test/other", field="twist.twist.linear.x")
    assert refused.status_code == 503 and refused.json()["error"] == "too_many_streams"
    assert ("/test/other", ODOM) not in echoes


def test_an_image_topic_is_refused_before_any_subscription(live_server, ros_peer):
    """Issue 27: plotting height of a camera decoded every 6 MB frame; now refused by type with a 422."""
    peer = ros_peer("camera_peer")
    peer.advertise("/test/image", "sensor_msgs/msg/Image")
    wait_until(lambda: listed(live_server, "/test/image"), 15, "topic listed")
    peer.publish("/test/image", {"height": 480, "width": 640, "encoding": "rgb8", "step": 1920,
                                 "data": [0] * (640 * 3 * 4)})
    for path in ("/api/plot", "/api/plot/fields"):
        refused = requests.get(live_server.url + path, params={"topic": "/test/image", "field": "height"}, timeout=5)
        assert refused.status_code == 422 and refused.json()["error"] == "not_plottable", path
    assert len(live_server.rover.feature(TopicBrowser).echoes) == 0  # nothing was subscribed
    assert live_server.rover.feature(Plots).active() == []


def test_messages_over_the_size_cap_are_dropped_unread(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_PLOT_MAX_MESSAGE_BYTES=4096)
    peer = ros_peer("array_peer")
    peer.advertise("/test/array", "std_msgs/msg/Float64MultiArray")
    wait_until(lambda: listed(server, "/test/array"), 15, "topic listed")
    assert plot(server, topic="/test/array", field="data[0]").status_code == 200
    peer.wait_match("/test/array")
    for i in range(3):
        peer.publish("/test/array", {"data": [float(i)] * 2000})  # 16 kB: over the cap
    peer.publish("/test/array", {"data": [7.0, 8.0]})  # small: plotted
    reply = wait_until(lambda: (r := plot(server, topic="/test/array", field="data[0]").json())["v"] and r, 10,
                       "the small message plotted")
    assert reply["v"] == [7.0]
    wait_until(lambda: plot(server, topic="/test/array", field="data[0]").json()["skipped_oversize"] == 3, 10,
               "three big messages dropped")


def test_one_user_cannot_take_every_series(live_server_factory, ros_peer, tmp_path):
    """Issue 27: a client holds at most ROVER_WEB_PLOT_SERIES_PER_CLIENT series; others still plot,
    and a series the client stopped asking for leaves its share after PLOT_IDLE_S."""
    from tests.conftest import _signed_settings

    settings, tokens = _signed_settings(tmp_path)
    server = live_server_factory(**settings, ROVER_WEB_PLOT_SERIES_PER_CLIENT=2, ROVER_WEB_PLOT_IDLE_S=1.0)
    peer = ros_peer("odom_peer")
    peer.advertise("/test/odom", ODOM)
    viewer = {"Authorization": f"Bearer {tokens['viewer']}"}
    operator = {"Authorization": f"Bearer {tokens['operator']}"}
    wait_until(lambda: any(t["name"] == "/test/odom" for t in requests.get(
        server.url + "/api/topics", headers=viewer, timeout=5).json()["topics"]), 15, "topic listed")

    def ask(headers, field):
        return requests.get(server.url + "/api/plot", params={"topic": "/test/odom", "field": field},
                            headers=headers, timeout=5)

    fields = ["pose.pose.position.x", "pose.pose.position.y", "pose.pose.position.z"]
    assert ask(viewer, fields[0]).status_code == 200 and ask(viewer, fields[1]).status_code == 200
    assert ask(viewer, fields[0]).status_code == 200  # asking again for one it has costs nothing
    third = ask(viewer, fields[2])
    assert third.status_code == 503 and third.json()["error"] == "too_many_series", third.text
    assert ask(operator, fields[2]).status_code == 200  # someone else still plots
    assert ask(operator, fields[0]).status_code == 200  # and shares the viewer's series
    # The viewer stops asking for its first two: after the idle time they are no longer its share.
    wait_until(lambda: ask(viewer, fields[2]).status_code == 200, 10, "the viewer's share freed")
