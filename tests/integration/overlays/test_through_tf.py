"""The overlays placed through TF published by a real rclpy peer in another process: a scan from a
laser mounted upside down, turned and off centre lands on a known wall; a pitched laser's returns
are projected in 3D; a marker in the laser's frame and a footprint in base_link follow TF; and with
no TF at all the same layers say they were placed by the configured offsets."""

import math
import time

import numpy as np
import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

TF = "tf2_msgs/msg/TFMessage"
SCAN = "sensor_msgs/msg/LaserScan"
MARKERS = "visualization_msgs/msg/MarkerArray"
POLYGON = "geometry_msgs/msg/PolygonStamped"
AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"


def stamp(t):
    sec = int(t)
    return {"sec": sec, "nanosec": int(round((t - sec) * 1e9))}


def transform(parent, child, xyz, q, t=0.0):
    return {"header": {"stamp": stamp(t), "frame_id": parent}, "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", map(float, xyz), strict=True)),
                          "rotation": dict(zip("xyzw", map(float, q), strict=True))}}


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def rpy_q(roll, pitch, yaw):  # tf2's setRPY: Rz(yaw) Ry(pitch) Rx(roll)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


# map -> odom (1, 2) turned 90°; odom -> base_link (3, 1) turned 90°: base_link is at map (0, 5) facing 180°.
# The laser "flipped": 0.15 m ahead, 0.08 m right, 0.25 m up, upside down and turned 0.5 rad left: its
# origin at map (0 - 0.15, 5 + 0.08) = (-0.15, 5.08), a beam at +a pointing at 180° + 0.5 - a.
# The laser "pitched": 0.2 m ahead, 0.4 m up, pitched 30° down, looking ahead: a return at r is
# r·cos 30° ahead of it on the map (and r·sin 30° lower).
FLIPPED_ORIGIN = (-0.15, 5.08)
WALL_X = -2.15  # a wall 2 m west of the flipped laser, along map y


@pytest.fixture
def tf_peer(ros_peer):
    peer = ros_peer("tf_overlay_peer")
    peer.advertise("/tf_static", TF, qos="latched")
    peer.publish("/tf_static", {"transforms": [
        transform("base_link", "flipped", (0.15, -0.08, 0.25), rpy_q(math.pi, 0.0, 0.5)),
        transform("base_link", "pitched", (0.2, 0.0, 0.4), rpy_q(0.0, math.pi / 6, 0.0))]})
    peer.advertise("/tf", TF, qos=100)
    for topic, kind in (("/scan", SCAN), ("/visualization_marker_array", MARKERS),
                        ("/global_costmap/published_footprint", POLYGON)):
        peer.advertise(topic, kind, qos="sensor_data" if kind == SCAN else 10)
    return peer


def publish_tf(peer, t0):
    """The robot stood still from t0 - 1 to t0 + 1 (a scan at t0 interpolates between them)."""
    for t in (t0 - 1.0, t0 + 1.0):
        peer.publish("/tf", {"transforms": [transform("map", "odom", (1, 2, 0), yaw_q(math.pi / 2), t),
                                            transform("odom", "base_link", (3, 1, 0), yaw_q(math.pi / 2), t)]})


def wall_scan(frame, t, angles, ranges):
    return {"header": {"frame_id": frame, "stamp": stamp(t)}, "angle_min": float(angles[0]),
            "angle_max": float(angles[-1]), "angle_increment": float(angles[1] - angles[0]),
            "range_min": 0.05, "range_max": 30.0, "ranges": [float(r) for r in ranges]}


def overlays(server):
    return requests.get(server.url + "/api/overlays", timeout=5).json()


def publish_until(peer, topic, msg, stream, channel, predicate, t0, timeout=15):
    def seen():
        publish_tf(peer, t0)
        peer.publish(topic, msg)
        return next((e["json"] for e in reversed(stream.of(channel)) if predicate(e["json"])), None)
    return wait_until(seen, timeout=timeout, interval=0.3, what=f"{channel} from {topic}")


def test_a_scan_from_an_upside_down_offset_laser_lands_on_the_known_wall(live_server, tf_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    t0 = time.time() - 2.0
    # Beams from a = 0.3 to 0.7 point at 180° + 0.2 ... 180° - 0.2: the wall 2 m west is 2 / |cos| away.
    angles = np.linspace(0.3, 0.7, 5)
    ranges = 2.0 / np.abs(np.cos(math.pi + 0.5 - angles))
    event = publish_until(tf_peer, "/scan", wall_scan("flipped", t0, angles, ranges), stream, "scan",
                          lambda d: d["frame_id"] == "flipped", t0)
    points = np.array(event["points"]).reshape(-1, 2)
    assert event["placed_by"] == "tf" and len(points) == 5
    assert points[:, 0] == pytest.approx(np.full(5, WALL_X), abs=0.01)        # on the wall
    # Beam a = 0.3 points at 180° + 0.2 (south of west), a = 0.7 at 180° - 0.2 (north of west).
    expected_y = FLIPPED_ORIGIN[1] + ranges * np.sin(math.pi + 0.5 - angles)
    assert points[:, 1] == pytest.approx(expected_y, abs=0.01)
    assert points[0, 1] < FLIPPED_ORIGIN[1] < points[-1, 1]
    assert event["pose"][:2] == pytest.approx(list(FLIPPED_ORIGIN), abs=1e-3)
    assert overlays(live_server)["layers"]["scan"]["placed_by"] == "tf"


def test_a_pitched_laser_s_returns_are_projected_in_3d(live_server, tf_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    t0 = time.time() - 2.0
    event = publish_until(tf_peer, "/scan", wall_scan("pitched", t0, [0.0, 0.1], [2.0, float("nan")]), stream,
                          "scan", lambda d: d["frame_id"] == "pitched", t0)
    # The laser is at base_link + 0.2 ahead: map (-0.2, 5); its return 2·cos 30° further west.
    assert event["points"] == pytest.approx([-0.2 - 2 * math.cos(math.pi / 6), 5.0], abs=0.01)


def test_the_3d_view_s_scan_keeps_the_laser_s_height_and_tilt(live_server, tf_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=scan3d")
    t0 = time.time() - 2.0
    event = publish_until(tf_peer, "/scan", wall_scan("pitched", t0, [0.0, 0.1], [2.0, float("nan")]), stream,
                          "scan3d", lambda d: d["frame_id"] == "pitched", t0)
    # 0.4 m up, pitched 30° down: the return 2·cos 30° ahead and 2·sin 30° below the laser, in 3D.
    assert event["placed_by"] == "tf"
    assert event["points"] == pytest.approx([-0.2 - 2 * math.cos(math.pi / 6), 5.0, 0.4 - 2 * math.sin(math.pi / 6)],
                                            abs=0.01)
    flat = publish_until(tf_peer, "/scan", wall_scan("flipped", t0, [0.5, 0.6], [2.0, 2.0]), stream, "scan3d",
                         lambda d: d["frame_id"] == "flipped", t0)
    assert np.array(flat["points"]).reshape(-1, 3)[:, 2] == pytest.approx([0.25, 0.25], abs=0.01)  # its height


def test_a_marker_in_the_laser_s_frame_and_a_footprint_in_base_link_follow_tf(live_server, tf_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=markers,footprint")
    t0 = time.time() - 2.0
    arrow = {"header": {"frame_id": "flipped", "stamp": stamp(t0)}, "ns": "sensor", "id": 1, "type": 0,
             "action": 0, "pose": {"position": {"x": 1.0}, "orientation": {"w": 1.0}},
             "scale": {"x": 1.0, "y": 0.1, "z": 0.1}, "color": {"r": 1.0, "a": 1.0}}
    event = publish_until(tf_peer, "/visualization_marker_array", {"markers": [arrow]}, stream, "markers",
                          lambda d: d["markers"], t0)
    m = event["markers"][0]
    heading = math.pi + 0.5  # the flipped laser's x axis on the map
    assert m["placed_by"] == "tf"
    assert m["pose"][:2] == pytest.approx([FLIPPED_ORIGIN[0] + math.cos(heading),
                                           FLIPPED_ORIGIN[1] + math.sin(heading)], abs=1e-3)
    assert math.cos(m["pose"][2] - heading) == pytest.approx(1.0, abs=1e-5)
    square = [{"x": x, "y": y} for x, y in ((0.3, 0.2), (-0.3, 0.2), (-0.3, -0.2), (0.3, -0.2))]
    foot = publish_until(tf_peer, "/global_costmap/published_footprint",
                         {"header": {"frame_id": "base_link", "stamp": stamp(t0)}, "polygon": {"points": square}},
                         stream, "footprint", lambda d: True, t0)
    # base_link at (0, 5) facing 180°: its front-left corner (0.3, 0.2) is at (-0.3, 4.8).
    assert foot["placed_by"] == "tf"
    assert np.array(foot["polygon"]).ravel() == pytest.approx([-0.3, 4.8, 0.3, 4.8, 0.3, 5.2, -0.3, 5.2], abs=1e-3)
    assert overlays(live_server)["layers"]["footprint"]["placed_by"] == "tf"


def test_without_tf_the_layers_say_they_were_placed_by_the_configured_offsets(live_server, ros_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    peer = ros_peer("no_tf_peer")
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    peer.publish("/amcl_pose", {"header": {"frame_id": "map"},
                                "pose": {"pose": {"position": {"x": 10.0, "y": 10.0}, "orientation": {"w": 1.0}}}})
    peer.advertise("/scan", SCAN, qos="sensor_data")

    def seen():
        peer.publish("/scan", wall_scan("flipped", 0.0, [0.0, 0.1], [2.0, float("nan")]))
        return next((e["json"] for e in reversed(stream.of("scan"))), None)
    event = wait_until(seen, timeout=15, interval=0.3, what="a scan placed without TF")
    # ROVER_WEB_SCAN_LASER_OFFSET (0, 0, 0) at AMCL's pose: 2 m east of (10, 10); nothing about "flipped".
    assert event["placed_by"] == "configured" and event["points"] == pytest.approx([12.0, 10.0])
    summary = overlays(live_server)
    assert summary["layers"]["scan"]["placed_by"] == "configured" and summary["tf"] is True


def test_a_plan_in_odom_is_drawn_in_the_map_through_tf(live_server, tf_peer, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=plan")
    tf_peer.advertise("/plan", "nav_msgs/msg/Path")
    t0 = time.time() - 2.0
    path = {"header": {"frame_id": "odom", "stamp": stamp(t0)},
            "poses": [{"pose": {"position": {"x": x, "y": 0.0}, "orientation": {"w": 1.0}}} for x in (0.0, 1.0)]}
    event = publish_until(tf_peer, "/plan", path, stream, "plan", lambda d: d["points"], t0)
    # odom's (0, 0) and (1, 0) in the map: (1, 2) and (1, 3) (odom is turned 90°).
    assert event["placed_by"] == "tf" and event["frame_id"] == "odom"
    assert np.array(event["points"]).ravel() == pytest.approx([1.0, 2.0, 1.0, 3.0], abs=1e-3)


def test_the_gps_fix_is_moved_from_the_antenna_to_base_link_through_tf(live_server, ros_peer, sse_client):
    from rover_web.sim.geodesy import geodetic_to_enu

    stream = sse_client(live_server.url + "/api/events?channels=fix,heading")
    peer = ros_peer("gps_tf_peer")
    peer.advertise("/tf_static", TF, qos="latched")
    # The antenna 0.5 m behind base_link and 0.2 m to its left.
    peer.publish("/tf_static", {"transforms": [transform("base_link", "gps", (-0.5, 0.2, 0.6), (0, 0, 0, 1))]})
    peer.advertise("/odom", "nav_msgs/msg/Odometry")               # the GPS heading topic by default
    peer.advertise("/fix", "sensor_msgs/msg/NavSatFix", qos="sensor_data")
    lat0, lng0 = 27.3742443, -82.4500873
    north = {"header": {"frame_id": "odom"}, "child_frame_id": "base_link",
             "pose": {"pose": {"orientation": {"z": math.sin(math.pi / 4), "w": math.cos(math.pi / 4)}}}}
    fix = {"header": {"frame_id": "gps"}, "status": {"status": 0, "service": 1},
           "latitude": lat0, "longitude": lng0, "altitude": 1.0, "position_covariance_type": 0}

    def seen():
        peer.publish("/odom", north)     # facing north (ENU yaw 90°)
        peer.publish("/fix", fix)
        return next((e["json"] for e in reversed(stream.of("fix")) if e["json"].get("placed_by") == "tf"), None)
    event = wait_until(seen, timeout=15, interval=0.3, what="a fix placed through TF")
    assert event["antenna_offset_m"] == pytest.approx([-0.5, 0.2])
    # Facing north, the antenna is 0.5 m south and 0.2 m west of the centre: the centre is 0.5 m north
    # and 0.2 m east of the fix.
    east, north_m = geodetic_to_enu(event["lat"], event["lng"], lat0, lng0)
    assert (east, north_m) == pytest.approx((0.2, 0.5), abs=0.01)
