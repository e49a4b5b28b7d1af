"""The overlays placed through a real TF buffer: a laser upside down, turned and off centre, a
footprint in base_link, a marker in the laser's frame, a costmap in odom, with hand-computed
map positions; extrapolation refused with tf2's reasons; the fallback used and named when TF does
not know a frame."""

import math
import time
import types

import numpy as np
import pytest

from rover_web import config
from rover_web.events.hub import EventHub
from rover_web.overlays.costmap import Grid
from rover_web.overlays.scan import Scan
from rover_web.overlays.service import OverlayService
from rover_web.placement import MapPlacer
from rover_web.tf.buffer import TfBuffer

S = 1_000_000_000


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def rpy_q(roll, yaw):  # Rz(yaw) Rx(roll)
    cr, sr, cy, sy = math.cos(roll / 2), math.sin(roll / 2), math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cy, sr * sy, cr * sy, cr * cy)


@pytest.fixture
def buffer():
    b = TfBuffer(cache_s=10.0)
    # map -> odom: (1, 2) turned +90 degrees; odom -> base_link: (3, 1) turned +90 degrees, at 10 s and 11 s.
    for t in (10, 11):
        b.set_transform("map", "odom", (1.0, 2.0, 0.0), yaw_q(math.pi / 2), t * S, static=False)
        b.set_transform("odom", "base_link", (3.0, 1.0, 0.0), yaw_q(math.pi / 2), t * S, static=False)
    # The laser: 15 cm ahead, 8 cm right, 25 cm up, upside down (roll 180) and turned 0.5 rad left.
    b.set_transform("base_link", "base_scan", (0.15, -0.08, 0.25), rpy_q(math.pi, 0.5), 0, static=True)
    return b


@pytest.fixture
def service(buffer):
    settings = config.defaults()
    hub = EventHub()
    hub.register("scan", "costmap", "markers", "footprint")
    s = OverlayService(types.SimpleNamespace(config=settings, hub=hub))
    s.placer = MapPlacer(buffer)
    yield s
    hub.close()


# By hand: base_link in map = (1, 2, 90°) ∘ (3, 1, 90°) = (1 - 1, 2 + 3, 180°) = (0, 5, 180°).
# The laser's origin: (0, 5) + R(180°)(0.15, -0.08) = (-0.15, 5.08); its x axis at 180° + 0.5 rad.
# Upside down, a beam at +a in the laser's frame points at (180° + 0.5 - a) in the map.
LASER = (-0.15, 5.08)


def scan_at(stamp, ranges, angle_min=0.5, frame="base_scan"):
    return Scan(frame, stamp, angle_min, 0.1, 0.05, 30.0, np.asarray(ranges, np.float32))


def wait_rate(service):
    time.sleep(1.0 / service.scan_max_hz)


def test_a_scan_from_the_upside_down_offset_laser_lands_where_tf_puts_it(service):
    # Beam 0 at a = 0.5 points at 180°: 2 m west of the laser. Beam 1 at a = 0.6: 180° - 0.1 rad.
    service.on_scan(scan_at(10.5, [2.0, 3.0]))
    event = service.hub.latest("scan")
    assert event["placed_by"] == "tf"
    points = np.array(event["points"]).reshape(-1, 2)
    assert points[0] == pytest.approx([LASER[0] - 2.0, LASER[1]], abs=0.01)
    theta = math.pi - 0.1
    assert points[1] == pytest.approx([LASER[0] + 3 * math.cos(theta), LASER[1] + 3 * math.sin(theta)], abs=0.01)
    assert event["pose"][:2] == pytest.approx(list(LASER), abs=1e-3)
    assert service.summary()["layers"]["scan"]["placed_by"] == "tf"


def test_a_far_return_among_near_ones_is_placed_too(service):
    service.scan_bins = 1
    service.on_scan(scan_at(10.5, [2.0, 2.0, 25.0, 2.0]))   # one bin; its farthest is the 25 m beam at a = 0.7
    event = service.hub.latest("scan")
    assert len(event["points"]) == 2
    theta = math.pi + 0.5 - 0.7
    assert event["far_points"] == pytest.approx([LASER[0] + 25 * math.cos(theta), LASER[1] + 25 * math.sin(theta)],
                                                abs=0.01)


def test_stamps_tf_cannot_reach_are_skipped_with_tf2_s_reason_but_a_little_ahead_takes_the_newest(service):
    service.on_scan(scan_at(12.0, [2.0]))     # 1 s after the newest transform
    service.on_scan(scan_at(0.5, [2.0]))      # before the cache's oldest
    assert service.counts["scan"].snapshot()["skipped_by_reason"] == {
        "tf_extrapolation_future": 1, "tf_extrapolation_past": 1}
    assert service.hub.latest("scan") is None
    service.on_scan(scan_at(11.1, [2.0]))     # 0.1 s ahead: tf2's MessageFilter would wait; we take the newest
    assert service.hub.latest("scan")["points"] == pytest.approx([LASER[0] - 2.0, LASER[1]], abs=0.01)


def test_a_frame_tf_does_not_know_falls_back_to_the_configured_offset_and_says_so(service):
    service.on_pose(10.5, 7.0, 8.0, 0.0)                    # AMCL's pose: the fallback's robot
    service.on_scan(scan_at(10.5, [2.0], angle_min=0.0, frame="base_laser"))
    event = service.hub.latest("scan")
    assert event["placed_by"] == "configured"               # ROVER_WEB_SCAN_LASER_OFFSET (0, 0, 0)
    assert event["points"] == pytest.approx([9.0, 8.0])
    assert service.summary()["layers"]["scan"]["placed_by"] == "configured"


def test_a_footprint_in_base_link_follows_tf(service):
    square = [(0.2, 0.2), (-0.2, 0.2), (-0.2, -0.2), (0.2, -0.2)]
    service.on_footprint("base_link", 10.5, square)
    f = service.hub.latest("footprint")
    assert f["placed_by"] == "tf"
    # base_link at (0, 5) facing 180°: its (+0.2, +0.2) corner is at (-0.2, 4.8).
    assert f["polygon"][0] == pytest.approx([-0.2, 4.8], abs=1e-3)
    assert f["polygon"][2] == pytest.approx([0.2, 5.2], abs=1e-3)


def marker(**kw):
    m = {"ns": "n", "id": 1, "type": 0, "action": 0, "frame_id": "base_scan", "stamp": 10.5,
         "pose": (1.0, 0.0, 0.0), "scale": (1.0, 0.1, 0.1), "color": (1.0, 0.0, 0.0, 1.0),
         "points": [], "colors": [], "text": "", "lifetime_s": 0.0}
    m.update(kw)
    return m


def test_a_marker_in_the_laser_s_frame_is_placed_through_tf_and_a_tilted_frame_s_points_too(service):
    service.on_markers([marker(), marker(id=2, type=4, pose=(0.0, 0.0, 0.0), points=[(0.0, 1.0), (1.0, 0.0)])])
    drawn = {m["id"]: m for m in service.hub.latest("markers")["markers"]}
    heading = math.pi + 0.5
    assert drawn[1]["placed_by"] == "tf"
    assert drawn[1]["pose"][:2] == pytest.approx([LASER[0] + math.cos(heading), LASER[1] + math.sin(heading)],
                                                 abs=1e-3)
    assert math.cos(drawn[1]["pose"][2] - heading) == pytest.approx(1.0, abs=1e-6)
    # The laser's +y points down the robot's -y (upside down): 1 m along it is at heading - 90°.
    left = heading - math.pi / 2
    assert drawn[2]["points"][0] == pytest.approx([LASER[0] + math.cos(left), LASER[1] + math.sin(left)], abs=1e-3)
    assert service.summary()["layers"]["markers"]["placed_by"] == "tf"


def test_a_costmap_in_odom_is_placed_with_tf_s_map_to_odom(service):
    service.costmap_max_hz = 1000.0
    service.on_costmap("/local_costmap/costmap", Grid("odom", 10.5, 2, 2, 0.5, (1.0, 0.0, 0.0), np.zeros(4, np.int8)))
    service.encode_costmaps()
    layer = service.costmaps()[0]
    # (1, 0) in odom: (1, 2) + R(90°)(1, 0) = (1, 3), turned 90°.
    assert layer["frame_id"] == "map" and layer["placed_by"] == "tf"
    assert layer["origin"] == pytest.approx([1.0, 3.0, math.pi / 2], abs=1e-6)
    assert service.summary()["costmaps_placed_by"] == {"/local_costmap/costmap": "tf"}
