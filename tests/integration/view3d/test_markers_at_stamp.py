"""The 3D view places markers as tf2 and RViz do, with a real rclpy peer in another process publishing a
moving robot's TF: a marker in base_link is where base_link was at the marker's stamp, not where it is
now; a marker stamped 0 or frame_locked follows its frame's latest pose (no `at_stamp`); one stamped
before anything the buffer holds is refused with tf2's reason (in every fixed frame but its own)."""

import time

import pytest
import requests

from tests.integration.overlays.test_through_tf import TF, stamp, transform
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

MARKERS = "visualization_msgs/msg/MarkerArray"


def cube(i, frame, t, frame_locked=False):
    return {"header": {"frame_id": frame, "stamp": stamp(t)}, "ns": "at_stamp", "id": i, "type": 1,
            "action": 0, "pose": {"position": {"x": 1.0}, "orientation": {"w": 1.0}},
            "scale": {"x": 0.2, "y": 0.2, "z": 0.2}, "color": {"g": 1.0, "a": 1.0}, "frame_locked": frame_locked}


def test_a_marker_is_placed_where_its_frame_was_at_its_stamp(live_server, ros_peer, sse_client):
    peer = ros_peer("moving_robot_peer")
    peer.advertise("/tf", TF, qos=100)
    peer.advertise("/visualization_marker_array", MARKERS)
    stream = sse_client(live_server.url + "/api/events?channels=view3d_markers,view3d")
    t_start = time.time() - 4.0

    def drive():
        """base_link drives along map x at 1 m/s from t_start (x = 0) to now (x = about 4)."""
        now = time.time()
        for t in [t_start + k * 0.5 for k in range(9)] + [now]:
            peer.publish("/tf", {"transforms": [transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), t),
                                                transform("odom", "base_link", (t - t_start, 0, 0), (0, 0, 0, 1), t),
                                                transform("base_link", "mast", (0, 0, 0.5), (0, 0, 0, 1), t)]})

    then = t_start + 1.5  # base_link was at x = 1.5
    array = {"markers": [cube(1, "base_link", then), cube(2, "base_link", 0.0), cube(3, "base_link", then, True),
                         cube(4, "base_link", then - 3600.0), cube(5, "mast", then - 3600.0)]}

    def seen():
        drive()
        peer.publish("/visualization_marker_array", array)
        return next((e["json"] for e in reversed(stream.of("view3d_markers"))
                     if {m["id"] for m in e["json"]["markers"]} >= {1, 2, 3}), None)
    event = wait_until(seen, timeout=20, interval=0.3, what="the markers in 3D")
    by_id = {m["id"]: m for m in event["markers"]}
    stamped = by_id[1]["at_stamp"]
    # base_link at the stamp, in each fixed frame: 1.5 m along map and odom (interpolated between two
    # transforms); in base_link itself, where it is.
    assert stamped["map"][:3] == pytest.approx([1.5, 0.0, 0.0], abs=1e-3)
    assert stamped["odom"][:3] == pytest.approx([1.5, 0.0, 0.0], abs=1e-3)
    assert stamped["base_link"] == pytest.approx([0, 0, 0, 0, 0, 0, 1], abs=1e-6)
    # The latest pose the page would otherwise use is far ahead (the robot kept driving).
    poses = wait_until(lambda: next((e["json"]["frames"] for e in reversed(stream.of("view3d"))
                                     if (e["json"]["frames"].get("map") or [None])[0] is not None), None),
                       10, "the poses")
    assert -poses["map"][0] > 3.0  # map seen from base_link: base_link is over 3 m along
    assert "at_stamp" not in by_id[2] and "at_stamp" not in by_id[3]  # stamp 0, frame_locked: the latest pose
    # An hour before the buffer: tf2 refuses it but in its own frame (a frame is itself at any time), so in
    # base_link it is drawn and in map or odom it is not; in the mast, refused everywhere: not kept, counted.
    assert set(by_id[4]["at_stamp"]) == {"base_link"}
    assert 5 not in by_id
    skipped = requests.get(live_server.url + "/api/3d/robot", timeout=5).json()["markers_skipped"]
    assert skipped.get("tf_extrapolation_past", 0) >= 1, skipped

