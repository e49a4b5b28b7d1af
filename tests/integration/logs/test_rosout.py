"""The /rosout log against real nodes: lines another process logs reach GET /api/rosout and the
`rosout` channel in batches, filters work, repeats are grouped, bad queries are 400 and the ring stays bounded."""

import pytest
import requests

from rover_web.logs.service import RosoutLog
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros


def rosout(server, **params):
    return requests.get(server.url + "/api/rosout", params=params, timeout=5)


def test_lines_logged_by_another_node_are_served_filtered_and_grouped(live_server, ros_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=rosout,rosout_health")
    peer = ros_peer("chatty_node")
    # Transient local: what the peer logged before the app subscribed still arrives, so no match wait.
    peer.log("starting up", "info")
    peer.log("debug detail", "debug")
    peer.log("battery low", "warning")
    peer.log("motor fault", "error")
    peer.log("retrying link", "warning", times=5)
    wait_until(lambda: any(x["msg"] == "retrying link" and x["count"] == 5
                           for x in rosout(live_server, node="chatty_node").json()["lines"]), 15, "lines served")

    lines = rosout(live_server, node="chatty").json()["lines"]
    assert [(x["msg"], x["level_name"], x["count"]) for x in lines] == [
        ("retrying link", "WARN", 5), ("motor fault", "ERROR", 1), ("battery low", "WARN", 1),
        ("debug detail", "DEBUG", 1), ("starting up", "INFO", 1)]
    assert lines[0]["node"] == "chatty_node" and lines[0]["stamp"] >= lines[0]["first_stamp"] > 0
    warn_up = rosout(live_server, level="WARN", node="chatty_node").json()["lines"]
    assert [x["msg"] for x in warn_up] == ["retrying link", "motor fault", "battery low"]
    assert [x["msg"] for x in rosout(live_server, contains="FAULT").json()["lines"]] == ["motor fault"]
    assert [x["msg"] for x in rosout(live_server, node="chatty_node", limit=2).json()["lines"]] == [
        "retrying link", "motor fault"]
    assert rosout(live_server, node="nobody_by_this_name").json()["lines"] == []

    # The channel carried them as batches (several lines per event), oldest first within each.
    def batched():
        return [x["msg"] for e in stream.of("rosout") for x in e["json"]["lines"] if x["node"] == "chatty_node"]

    wait_until(lambda: len(batched()) >= 9, 5, "nine lines on the channel")
    batched = batched()
    assert batched[:4] == ["starting up", "debug detail", "battery low", "motor fault"] and len(batched) == 9
    assert len([e for e in stream.of("rosout")]) < len(batched)
    # Lines are numbered, batches run on without a hole, and the API says where the ring is.
    events = [e["json"] for e in stream.of("rosout")]
    assert all(b["first_seq"] == a["last_seq"] + 1 for a, b in zip(events, events[1:], strict=False))
    assert rosout(live_server).json()["last_seq"] == events[-1]["last_seq"]
    # And the health bar counts the error.
    stream.wait_for("rosout_health", lambda h: h["errors_last_minute"] >= 1, timeout=5)


@pytest.mark.parametrize("params,code", [({"level": "LOUD"}, "bad_level"), ({"limit": "0"}, "bad_limit"),
                                         ({"limit": "ten"}, "bad_limit"), ({"limit": "999999999"}, "bad_limit"),
                                         ({"contains": "x" * 201}, "bad_contains"),
                                         ({"color": "red"}, "unknown_parameter")])
def test_bad_queries_are_400_json(live_server, params, code):
    reply = rosout(live_server, **params)
    assert reply.status_code == 400 and reply.json()["error"] == code and reply.json()["message"]


def test_the_ring_is_bounded_by_the_setting(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_ROSOUT_KEEP=50)
    peer = ros_peer("flood_node")
    peer.log("flood", "info", times=300)
    log = server.rover.feature(RosoutLog)
    wait_until(lambda: log.received >= 300, 15, "300 lines received")
    assert len(log.ring) == 50
    reply = rosout(server, node="flood_node", limit=50).json()
    assert reply["kept"] == 50 and reply["lines"][0]["count"] == 50


def test_the_logs_page_renders_with_the_lines_in_it(live_server, ros_peer):
    peer = ros_peer("page_node")
    peer.log("visible on the page", "warning")
    wait_until(lambda: rosout(live_server, node="page_node").json()["lines"], 15, "line served")
    page = requests.get(live_server.url + "/logs", timeout=5).text
    assert "visible on the page" in page and "page_node" in page


def test_a_huge_line_from_another_node_is_kept_cut(live_server, ros_peer):
    """Issue 27: lines were kept whole (5,000 one-megabyte lines, 5 GB)."""
    peer = ros_peer("verbose_node")
    peer.log("start " + "z" * 200_000 + " end", "error")
    wait_until(lambda: rosout(live_server, node="verbose_node").json()["lines"], 15, "the line served")
    line = rosout(live_server, node="verbose_node").json()["lines"][0]
    assert line["msg"].startswith("start zzz") and line["msg"].endswith("more characters cut]")
    assert len(line["msg"]) < 4100 and " end" not in line["msg"]
    assert live_server.rover.feature(RosoutLog).ring.bytes < 100_000  # the whole ring, less than the line was
