"""The overlay service counts and skips what it cannot draw, and never lets a bad message through;
markers are kept as RViz keeps them; the pose at a scan's stamp is interpolated."""

import math
import time
import types

import numpy as np
import pytest

from rover_web import config
from rover_web.events.hub import EventHub
from rover_web.overlays.costmap import Grid
from rover_web.overlays.markers import BadMarker, MarkerSet
from rover_web.overlays.poses import PoseHistory
from rover_web.overlays.scan import Scan
from rover_web.overlays.service import OverlayService, laser_offset


@pytest.fixture
def service():
    settings = config.defaults()
    hub = EventHub()
    hub.register("scan", "costmap", "markers", "footprint")
    rover = types.SimpleNamespace(config=settings, hub=hub)
    yield OverlayService(rover)
    hub.close()


def marker(**kw):
    m = {"ns": "n", "id": 1, "type": 2, "action": 0, "frame_id": "map", "pose": (1.0, 2.0, 0.0),
         "scale": (1.0, 1.0, 1.0), "color": (1.0, 0.0, 0.0, 1.0), "points": [], "colors": [], "text": "",
         "lifetime_s": 0.0}
    m.update(kw)
    return m


def test_bad_scans_are_counted_by_reason_and_publish_nothing(service):
    service.on_scan(Scan("laser", 0.0, 0.0, 0.1, 0.1, 10.0, np.array([1.0], np.float32)))   # no pose yet
    service.on_pose(0.0, 1.0, 1.0, 0.0)
    service.on_scan(Scan("laser", 0.0, 0.0, 0.1, 0.1, 10.0, np.zeros(0, np.float32)))
    service.on_scan(Scan("laser", 0.0, math.inf, 0.1, 0.1, 10.0, np.ones(5, np.float32)))
    c = service.counts["scan"].snapshot()
    assert c["skipped_by_reason"] == {"no_pose": 1, "empty": 1, "bad_header": 1}
    assert c["received"] == 3 and c["converted"] == 0
    assert service.hub.latest("scan") is None
    # Only NaN beams: nothing seen, sent empty so the page drops the last points; the beams are counted.
    service.on_scan(Scan("laser", 0.0, 0.0, 0.1, 0.1, 10.0, np.full(5, np.nan, np.float32)))
    assert service.hub.latest("scan")["points"] == []
    assert service.counts["scan"].snapshot()["dropped_items"] == 5
    time.sleep(1.0 / service.scan_max_hz)   # past the channel's rate limit
    service.on_scan(Scan("laser", 0.0, 0.0, 0.1, 0.1, 10.0, np.array([2.0, np.nan], np.float32)))
    assert service.hub.latest("scan")["points"] == [3.0, 1.0]


def test_bad_costmaps_and_footprints_are_counted(service):
    service.on_costmap("/c", Grid("map", 0.0, 10, 10, 0.05, (0.0, 0.0, 0.0), np.zeros(5, np.int8)))
    service.on_costmap("/c", Grid("odom", 0.0, 2, 2, 0.05, (0.0, 0.0, 0.0), np.zeros(4, np.int8)))
    service.on_costmap("/c", Grid("map", 0.0, 2, 2, math.nan, (0.0, 0.0, 0.0), np.zeros(4, np.int8)))
    service.encode_costmaps()
    assert service.hub.latest("costmap") is None
    assert service.counts["costmap"].snapshot()["skipped_by_reason"] == {
        "size_mismatch": 1, "unknown_frame": 1, "bad_header": 1}
    service.on_footprint("map", 0.0, [(0.0, 0.0), (math.nan, 1.0), (1.0, 1.0)])
    service.on_footprint("map", 0.0, [])
    service.on_footprint("base_link", 0.0, [(0.0, 0.0), (1.0, 1.0)])   # no pose yet
    assert service.counts["footprint"].snapshot()["skipped_by_reason"] == {"not_finite": 1, "empty": 1, "no_pose": 1}
    assert service.hub.latest("footprint") is None


def test_costmaps_are_encoded_by_the_loop_newest_first_and_all_together(service):
    service.on_costmap("/global_costmap/costmap", Grid("map", 0.0, 2, 2, 0.5, (0.0, 0.0, 0.0),
                                                       np.array([0, 100, -1, 50], np.int8)))
    for value in (1, 2):   # two grids before the loop runs: only the newest is encoded
        service.on_costmap("/local_costmap/costmap", Grid("map", 0.0, 1, 1, 0.5, (0.0, 0.0, 0.0),
                                                          np.array([value], np.int8)))
    service.encode_costmaps()
    layers = service.hub.latest("costmap")["costmaps"]
    assert [c["topic"] for c in layers] == ["/global_costmap/costmap", "/local_costmap/costmap"]
    assert service.counts["costmap"].snapshot()["converted"] == 2
    # Too soon for another encoding: the new grid waits for the loop's next turn.
    service.on_costmap("/local_costmap/costmap", Grid("map", 0.0, 1, 1, 0.5, (0.0, 0.0, 0.0), np.array([3], np.int8)))
    service.encode_costmaps()
    assert service.hub.latest("costmap")["costmaps"] == layers
    # Then only the grid that changed carries its cells; the API has them all.
    service._next_encode = 0.0
    service.encode_costmaps()
    global_layer, local_layer = service.hub.latest("costmap")["costmaps"]
    assert global_layer["data"] is None and global_layer["seq"] == layers[0]["seq"]
    assert local_layer["data"] is not None and local_layer["seq"] > layers[1]["seq"]
    assert [c["data"] is not None for c in service.costmaps()] == [True, True]


def test_markers_add_replace_delete_and_expire():
    markers = MarkerSet(max_points=5)
    markers.apply(marker(), None, 0.0)
    markers.apply(marker(pose=(3.0, 4.0, 0.0)), None, 0.0)                 # same ns and id: replaced
    assert [m["pose"][:2] for m in markers.markers.values()] == [[3.0, 4.0]]
    markers.apply(marker(id=2, type=4, points=[(0.0, 0.0), (1.0, 0.0)], lifetime_s=1.0), None, 0.0)
    assert len(markers.markers) == 2
    with pytest.raises(BadMarker, match="too_many_points"):
        markers.apply(marker(id=3, type=8, points=[(0.0, 0.0)] * 4), None, 0.0)
    with pytest.raises(BadMarker, match="unsupported_type"):
        markers.apply(marker(id=4, type=10), None, 0.0)   # a mesh
    with pytest.raises(BadMarker, match="no_pose"):
        markers.apply(marker(id=5, frame_id="base_link"), None, 0.0)
    assert markers.expire(1.5) and len(markers.markers) == 1
    markers.apply(marker(id=3, type=8, points=[(0.0, 0.0)] * 4), None, 0.0)   # the expired line's points are free again
    assert markers.points == 4
    markers.apply(marker(action=2), None, 2.0)
    markers.apply(marker(id=3, action=2), None, 2.0)
    assert markers.markers == {} and markers.points == 0


def test_markers_in_the_robot_frame_follow_its_pose():
    markers = MarkerSet()
    markers.apply(marker(frame_id="base_link", type=0, pose=(1.0, 0.0, 0.0)), (2.0, 3.0, math.pi / 2), 0.0)
    (m,) = markers.markers.values()
    assert m["pose"] == pytest.approx([2.0, 4.0, math.pi / 2], abs=1e-3)


def test_the_pose_at_a_stamp_is_interpolated_and_a_stamp_before_the_history_finds_nothing():
    poses = PoseHistory()
    poses.add(10.0, 0.0, 0.0, 0.0)
    poses.add(11.0, 1.0, 2.0, math.pi / 2)
    assert poses.at(10.5) == pytest.approx((0.5, 1.0, math.pi / 4))
    assert poses.at(20.0) == (1.0, 2.0, math.pi / 2)       # after the newest: the robot stood still
    assert poses.at(9.5) == (0.0, 0.0, 0.0)                # just before the oldest
    assert poses.at(5.0) is None
    assert poses.path() == [[0.0, 0.0], [1.0, 2.0]]


def test_the_laser_offset_setting_must_be_three_numbers():
    assert laser_offset({"ROVER_WEB_SCAN_LASER_OFFSET": ["0.2", "-0.1", "3.14"]}) == (0.2, -0.1, 3.14)
    for bad in (["0", "0"], ["a", "0", "0"], ["nan", "0", "0"]):
        with pytest.raises(config.ConfigError, match="ROVER_WEB_SCAN_LASER_OFFSET"):
            laser_offset({"ROVER_WEB_SCAN_LASER_OFFSET": bad})
