"""Hostile overlay publishers (issue 40): a real peer in another process publishes what the third
security review did; the app drops what is too long before deserializing it, caps markers by count
before converting them, truncates their strings, and does no marker or scan work while no page watches."""

import time

import pytest

from rover_web.overlays import bounds
from tests.integration.overlays import test_ros
from tests.integration.overlays.test_ros import costmap, counts, publish_until
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

posed = test_ros.posed  # the fixture: a peer with the robot posed and every overlay topic advertised
WHITE = {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0}


def cube(i, ns="hostile", text=""):
    return {"header": {"frame_id": "map"}, "ns": ns, "id": i, "type": 1, "action": 0,
            "pose": {"position": {"x": 1.0, "y": 1.0}, "orientation": {"w": 1.0}},
            "scale": {"x": 0.1, "y": 0.1, "z": 0.1}, "color": WHITE, "text": text}


def test_markers_are_capped_by_count_and_size_before_conversion_and_strings_truncated(live_server, posed,
                                                                                     sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=markers")
    posed.wait_match("/visualization_marker_array")
    long_ns, long_text = "n" * 5000, "t" * 5000
    event = publish_until(posed, "/visualization_marker_array", {"markers": [cube(0, long_ns, long_text)]}, stream,
                          "markers", lambda d: len(d["markers"]) == 1)
    assert len(event["markers"][0]["ns"]) == bounds.NS_MAX and len(event["markers"][0]["text"]) == bounds.TEXT_MAX
    # 1,500 zero-point cubes in one array (under the byte bound): the first 1,000 converted, the rest counted.
    posed.publish("/visualization_marker_array", {"markers": [cube(i) for i in range(1500)]})
    event = stream.wait_for("markers", lambda d: len(d["markers"]) >= 1000, timeout=20)["json"]
    assert len(event["markers"]) == bounds.MARKERS_MAX_COUNT
    assert counts(live_server.url, "markers")["skipped_by_reason"]["too_many_markers"] >= 500
    # 3,000 cubes with long names: over the byte bound, dropped undeserialized, the set unchanged.
    posed.publish("/visualization_marker_array", {"markers": [cube(5000 + i, "x" * 400) for i in range(3000)]})
    wait_until(lambda: counts(live_server.url, "markers")["skipped_by_reason"].get("too_large", 0) >= 1, 20,
               "the long array counted too_large")
    assert all(len(e["json"]["markers"]) <= bounds.MARKERS_MAX_COUNT for e in stream.of("markers"))


def test_a_grid_longer_than_the_cell_bound_is_dropped_before_deserializing(live_server_factory, posed, sse_client):
    server = live_server_factory(ROVER_WEB_COSTMAP_MAX_CELLS=10_000)
    stream = sse_client(server.url + "/api/events?channels=costmap")
    posed.wait_match("/global_costmap/costmap")
    publish_until(posed, "/global_costmap/costmap", costmap(10, 10), stream, "costmap")
    # It says 10 x 10 and holds 50,000 cells: read whole, it was a size_mismatch after the copy.
    posed.publish("/global_costmap/costmap", costmap(10, 10, cells=[0] * 50_000))
    wait_until(lambda: counts(server.url, "costmap")["skipped_by_reason"].get("too_large", 0) >= 1, 15,
               "the long grid counted too_large")
    assert "size_mismatch" not in counts(server.url, "costmap")["skipped_by_reason"]


def test_markers_are_not_read_while_no_page_watches(live_server, posed, sse_client):
    posed.wait_match("/visualization_marker_array")
    for i in range(10):
        posed.publish("/visualization_marker_array", {"markers": [cube(i)]})
        time.sleep(0.1)
    time.sleep(1.0)  # matched before the first: each was delivered, and none was read
    assert counts(live_server.url, "markers")["received"] == 0
    stream = sse_client(live_server.url + "/api/events?channels=markers")
    publish_until(posed, "/visualization_marker_array", {"markers": [cube(99)]}, stream, "markers",
                  lambda d: len(d["markers"]) >= 1)
    assert counts(live_server.url, "markers")["received"] >= 1
