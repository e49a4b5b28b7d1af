"""LiveMap overlays with real ROS publishers in other processes: each layer arrives on its channel,
bad messages are skipped and counted, and the simulator publishes every layer."""

import math

import numpy as np
import pytest
import requests

from rover_web.overlays.costmap import decode
from rover_web.sim.frames import LASER, laser_origin
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"
SCAN = "sensor_msgs/msg/LaserScan"
GRID = "nav_msgs/msg/OccupancyGrid"
MARKERS = "visualization_msgs/msg/MarkerArray"
POLYGON = "geometry_msgs/msg/PolygonStamped"


def amcl(x, y, yaw=0.0):
    return {"header": {"frame_id": "map"},
            "pose": {"pose": {"position": {"x": x, "y": y},
                              "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}}


def laser(ranges, frame="base_scan"):
    n = len(ranges)
    return {"header": {"frame_id": frame}, "angle_min": -math.pi, "angle_max": math.pi - 2 * math.pi / max(n, 1),
            "angle_increment": 2 * math.pi / max(n, 1), "range_min": 0.05, "range_max": 20.0, "ranges": ranges}


def costmap(width, height, cells=None, origin=(1.0, 2.0), resolution=0.05):
    return {"header": {"frame_id": "map"},
            "info": {"width": width, "height": height, "resolution": resolution,
                     "origin": {"position": {"x": origin[0], "y": origin[1]}, "orientation": {"w": 1.0}}},
            "data": cells if cells is not None else [0] * (width * height)}


def counts(url, layer):
    return requests.get(url + "/api/overlays", timeout=5).json()["layers"][layer]


def publish_until(peer, topic, msg, stream, channel, predicate=lambda d: True, timeout=15):
    """Publish until the channel shows a value the predicate accepts (discovery takes a moment)."""
    def seen():
        peer.publish(topic, msg)
        return next((e["json"] for e in reversed(stream.of(channel)) if predicate(e["json"])), None)
    return wait_until(seen, timeout=timeout, interval=0.3, what=f"{channel} from {topic}")


@pytest.fixture
def posed(ros_peer):
    """A peer with the robot at (10, 10) facing +y (AMCL's pose, latched), and every overlay topic advertised."""
    peer = ros_peer("overlay_peer")
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    peer.publish("/amcl_pose", amcl(10.0, 10.0, math.pi / 2))
    peer.advertise("/scan", SCAN, qos="sensor_data")
    peer.advertise("/global_costmap/costmap", GRID, qos="latched")
    peer.advertise("/visualization_marker_array", MARKERS)
    peer.advertise("/global_costmap/published_footprint", POLYGON)
    return peer


def test_a_dense_scan_is_thinned_keeping_its_nearest_return_and_placed_at_the_robot_s_pose(
        live_server, posed, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    ranges = [3.0] * 1080
    ranges[540] = 0.7            # straight ahead (angle 0): one beam nearer than its neighbours
    ranges[541] = 0.9
    ranges[100:110] = [float("nan")] * 10
    ranges[200] = float("inf")
    ranges[300] = 0.01           # below range_min: no return
    event = publish_until(posed, "/scan", laser(ranges), stream, "scan")
    assert event["beams"] == 1080 and event["frame_id"] == "base_scan"
    assert event["pose"][:2] == [10.0, 10.0]
    points = np.array(event["points"]).reshape(-1, 2)
    assert len(points) <= 360
    # Robot facing +y: the laser's angle 0 is map +y, so the near return is 0.7 m north of the robot.
    assert np.min(np.hypot(points[:, 0] - 10.0, points[:, 1] - 10.7)) < 0.011
    assert np.hypot(points[:, 0] - 10.0, points[:, 1] - 10.0).min() == pytest.approx(0.7, abs=0.01)
    assert np.hypot(points[:, 0] - 10.0, points[:, 1] - 10.0).max() == pytest.approx(3.0, abs=0.01)
    c = counts(live_server.url, "scan")
    assert c["converted"] >= 1 and c["dropped_items"] >= 12
    assert set(c["skipped_by_reason"]) <= {"no_pose"}   # scans that came before the first pose did


def test_bad_messages_are_skipped_and_counted_and_good_ones_still_arrive(live_server_factory, posed, sse_client):
    server = live_server_factory(ROVER_WEB_COSTMAP_MAX_CELLS=10_000)
    stream = sse_client(server.url + "/api/events?channels=scan,costmap,markers,footprint")
    for topic in ("/scan", "/global_costmap/costmap", "/visualization_marker_array",
                  "/global_costmap/published_footprint"):
        posed.wait_match(topic)   # the app's subscriptions match before the bad messages go out
    publish_until(posed, "/scan", laser([2.0] * 90), stream, "scan")
    posed.publish("/scan", laser([]))                                    # empty
    # No valid return at all: nothing seen, sent empty (the last points must not stay up), beams counted.
    publish_until(posed, "/scan", laser([float("nan")] * 90), stream, "scan", lambda d: d["points"] == [])
    assert counts(server.url, "scan")["dropped_items"] >= 90
    # The costmap topic keeps one message (transient local, depth 1): one at a time, each heard.
    for bad_grid in (costmap(200, 200),             # 40,000 cells: over the cap
                     costmap(20, 20, [0] * 399),    # data shorter than its size
                     costmap(0, 0, [])):            # empty
        heard = counts(server.url, "costmap")["received"]
        posed.publish("/global_costmap/costmap", bad_grid)
        wait_until(lambda h=heard: counts(server.url, "costmap")["received"] > h, what="the grid heard")
    bad_marker = {"header": {"frame_id": "map"}, "ns": "bad", "id": 1, "type": 2, "action": 0,
                  "pose": {"position": {"x": float("nan")}, "orientation": {"w": 1.0}},
                  "scale": {"x": 1.0, "y": 1.0, "z": 1.0}, "color": {"r": 1.0, "a": 1.0}}
    odd_frame = {**bad_marker, "header": {"frame_id": "camera_optical"},
                 "pose": {"position": {"x": 1.0}, "orientation": {"w": 1.0}}}
    posed.publish("/visualization_marker_array", {"markers": [bad_marker, odd_frame]})
    posed.publish("/visualization_marker_array", {"markers": []})
    posed.publish("/global_costmap/published_footprint", {"header": {"frame_id": "map"}, "polygon": {"points": []}})

    def skipped():
        layers = requests.get(server.url + "/api/overlays", timeout=5).json()["layers"]
        reasons = {name: layer["skipped_by_reason"] for name, layer in layers.items()}
        want = {"scan": {"empty": 1},
                "costmap": {"too_large": 1, "size_mismatch": 1, "empty": 1},
                "markers": {"not_finite": 1, "unknown_frame": 1, "empty": 1}, "footprint": {"empty": 1}}
        # At least these (a scan before the first pose may add `no_pose`).
        return reasons if all(reasons[k].get(r, 0) >= n for k, v in want.items() for r, n in v.items()) else None

    wait_until(skipped, timeout=10, what="every bad message counted by its reason")
    # Nothing crashed: the app answers, and a good message of each kind still goes through.
    assert requests.get(server.url + "/api/status", timeout=5).json()["callback_errors"] == 0
    publish_until(posed, "/global_costmap/costmap", costmap(50, 40), stream, "costmap",
                  lambda d: d["costmaps"] and d["costmaps"][0]["width"] == 50)
    publish_until(posed, "/scan", laser([1.5] * 90), stream, "scan", lambda d: len(d["points"]) == 180)
    page = requests.get(server.url + "/livemap/Science%20Hall%20Basement", timeout=5).text
    assert 'id="overlay-skipped-costmap"' in page


def test_a_costmap_arrives_encoded_and_decodes_to_the_cells_sent(live_server, posed, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=costmap")
    cells = np.zeros((400, 400), dtype=np.int8)
    cells[10, 20:30] = 100          # a lethal wall, row 10 from the origin
    cells[200:210, 300] = 60        # inflation
    cells[399, :] = -1              # unknown top row
    msg = costmap(400, 400, cells.ravel().tolist())
    event = publish_until(posed, "/global_costmap/costmap", msg, stream, "costmap",
                          lambda d: d["costmaps"] and d["costmaps"][0]["width"] == 400)
    layer = event["costmaps"][0]
    assert layer["topic"] == "/global_costmap/costmap" and layer["encoding"] == "deflate-base64"
    assert layer["origin"][:2] == [1.0, 2.0] and layer["resolution"] == pytest.approx(0.05)
    got = decode(layer["data"], 400, 400)
    expected = cells.astype(np.int16)
    expected[expected < 0] = 255
    assert (got == expected).all()
    assert len(layer["data"]) < 5000      # 160,000 cells, mostly free: a few kilobytes
    # The API has every costmap's cells for a page that opens later; a bad query is a clear 400.
    summary = requests.get(live_server.url + "/api/overlays?costmaps=1", timeout=5).json()
    assert summary["costmaps"][0]["data"] == layer["data"]
    bad = requests.get(live_server.url + "/api/overlays?costmaps=yes", timeout=5)
    assert bad.status_code == 400 and bad.json()["error"] == "bad_costmaps"


def test_markers_and_a_footprint_arrive_in_the_map_frame(live_server, posed, sse_client):
    stream = sse_client(live_server.url + "/api/events?channels=markers,footprint")
    white = {"r": 1.0, "g": 1.0, "b": 1.0, "a": 1.0}

    def marker(i, kind, frame="map", points=(), text="", x=0.0, y=0.0):
        return {"header": {"frame_id": frame}, "ns": "test", "id": i, "type": kind, "action": 0,
                "pose": {"position": {"x": x, "y": y}, "orientation": {"w": 1.0}},
                "scale": {"x": 0.3, "y": 0.3, "z": 0.3}, "color": white,
                "points": [{"x": float(px), "y": float(py)} for px, py in points], "text": text}

    array = {"markers": [marker(1, 8, points=[(1, 1), (2, 2)]), marker(2, 4, points=[(0, 0), (5, 0), (5, 5)]),
                         marker(3, 2, x=3.0, y=4.0), marker(4, 0, frame="base_link", x=1.0),
                         marker(5, 9, text="dock", x=6.0, y=7.0)]}
    event = publish_until(posed, "/visualization_marker_array", array, stream, "markers",
                          lambda d: len(d["markers"]) == 5)
    kinds = {m["id"]: m for m in event["markers"]}
    assert [kinds[i]["type"] for i in range(1, 6)] == ["points", "line_strip", "sphere", "arrow", "text"]
    assert kinds[2]["points"] == [[0, 0], [5, 0], [5, 5]]
    assert kinds[3]["pose"][:2] == [3.0, 4.0]
    assert kinds[4]["pose"][:2] == pytest.approx([10.0, 11.0])     # 1 m ahead of a robot at (10, 10) facing +y
    assert kinds[5]["text"] == "dock"
    # DELETE removes one; DELETEALL clears them.
    posed.publish("/visualization_marker_array", {"markers": [{**marker(3, 2), "action": 2}]})
    stream.wait_for("markers", lambda d: len(d["markers"]) == 4)
    posed.publish("/visualization_marker_array", {"markers": [{**marker(0, 0), "action": 3}]})
    stream.wait_for("markers", lambda d: d["markers"] == [])
    # A footprint in base_link is placed with the robot's pose.
    square = [{"x": x, "y": y} for x, y in ((0.2, 0.2), (-0.2, 0.2), (-0.2, -0.2), (0.2, -0.2))]
    event = publish_until(posed, "/global_costmap/published_footprint",
                          {"header": {"frame_id": "base_link"}, "polygon": {"points": square}}, stream, "footprint")
    assert event["polygon"][0] == pytest.approx([9.8, 10.2])


def test_the_simulator_publishes_every_layer(live_server, sim_process, sse_client):
    sim_process("--only", "rover")
    stream = sse_client(live_server.url + "/api/events?channels=scan,costmap,markers,footprint")
    for channel in ("scan", "markers", "footprint"):
        stream.wait_for(channel, timeout=30)
    event = stream.wait_for("costmap", lambda d: len(d["costmaps"]) == 2, timeout=30)["json"]
    assert [c["topic"] for c in event["costmaps"]] == ["/global_costmap/costmap", "/local_costmap/costmap"]
    # Its laser is mounted upside down, turned and off centre (sim/frames.py): placed through TF.
    scan = stream.wait_for("scan", lambda d: d["points"] and d["placed_by"] == "tf")["json"]
    assert scan["frame_id"] == "base_scan" and scan["beams"] == 360
    # The basement's Dock (2.0, 10.5) has a wall 1.85 m to its west: the scan sees it there.
    points = np.array(scan["points"]).reshape(-1, 2)
    assert np.hypot(points[:, 0] - 0.15, points[:, 1] - 10.5).min() < 0.1
    # And every return lies on a wall of the floorplan (within a cell and a half).
    assert on_walls(points) == 1.0
    markers = stream.wait_for("markers", lambda d: {"text", "arrow"} <= {m["type"] for m in d["markers"]})["json"]
    assert {m["type"] for m in markers["markers"]} >= {"sphere", "text", "line_strip", "arrow"}
    assert next(m for m in markers["markers"] if m["type"] == "arrow")["placed_by"] == "tf"  # in base_link
    trail = requests.get(live_server.url + "/api/overlays", timeout=5).json()
    # Nothing the simulator sends is bad (what came before TF and the first pose cannot be placed, though).
    assert set(trail["layers"]["scan"]["skipped_by_reason"]) <= {"no_pose"}
    # The local costmap is in odom: one latched before the first TF cannot be placed yet (its frame
    # unknown, or known by then but only from transforms newer than the grid's stamp).
    assert set(trail["layers"]["costmap"]["skipped_by_reason"]) <= {"unknown_frame", "tf_extrapolation_past"}
    assert set(trail["layers"]["markers"]["skipped_by_reason"]) <= {"no_pose"}
    assert {trail["layers"][name]["placed_by"] for name in ("scan", "footprint")} == {"tf"}
    assert trail["costmaps_placed_by"] == {"/global_costmap/costmap": "map", "/local_costmap/costmap": "tf"}


def on_walls(points, within_m=0.075):
    """The share of points within `within_m` of an occupied cell of the simulator's floorplan."""
    from rover_web.sim.rover import first_map
    from rover_web.sim.sensors import Floorplan

    plan = Floorplan.from_definition(first_map())
    rows, cols = np.nonzero(plan.walls)
    centres = np.column_stack((plan.origin_x + (cols + 0.5) * plan.resolution,
                               plan.origin_y + (rows + 0.5) * plan.resolution))
    near = [np.min(np.abs(centres - p).max(axis=1)) <= within_m + plan.resolution / 2 for p in points]
    return float(np.mean(near))


def test_a_local_costmap_and_footprint_in_odom_are_placed_with_amcl_s_map_to_odom(live_server, posed, sse_client):
    """Nav2's local costmap and footprint are in `odom`: placed as AMCL's map -> odom puts them."""
    stream = sse_client(live_server.url + "/api/events?channels=costmap,footprint")
    posed.advertise("/odom", "nav_msgs/msg/Odometry")
    posed.advertise("/local_costmap/costmap", GRID, qos="latched")
    # Odometry has the robot 1 m along odom's x; AMCL has it at (10, 10) facing map +y (the fixture):
    # map_T_odom is then (10, 9) turned by +90 degrees.
    odom = {"header": {"frame_id": "odom"}, "child_frame_id": "base_link",
            "pose": {"pose": {"position": {"x": 1.0}, "orientation": {"w": 1.0}}}}
    posed.wait_match("/odom")
    grid = {**costmap(20, 10, origin=(1.0, 2.0)), "header": {"frame_id": "odom"}}

    def placed():
        posed.publish("/odom", odom)
        posed.publish("/local_costmap/costmap", grid)
        return next((e["json"] for e in reversed(stream.of("costmap"))
                     if any(c["topic"] == "/local_costmap/costmap" for c in e["json"]["costmaps"])), None)
    event = wait_until(placed, timeout=15, interval=0.3, what="the local costmap placed")
    layer = next(c for c in event["costmaps"] if c["topic"] == "/local_costmap/costmap")
    assert layer["origin"][0] == pytest.approx(8.0, abs=1e-3) and layer["origin"][1] == pytest.approx(10.0, abs=1e-3)
    assert layer["origin"][2] == pytest.approx(math.pi / 2, abs=1e-4)
    posed.advertise("/global_costmap/published_footprint", POLYGON)
    square = {"header": {"frame_id": "odom"},
              "polygon": {"points": [{"x": 1.0, "y": 0.0}, {"x": 2.0, "y": 0.0}, {"x": 2.0, "y": 1.0}]}}
    foot = publish_until(posed, "/global_costmap/published_footprint", square, stream, "footprint")
    assert foot["polygon"] == [[10.0, 10.0], [10.0, 11.0], [9.0, 11.0]]


def test_after_an_initial_pose_the_simulator_s_map_to_odom_moves_and_its_scan_still_lies_on_the_walls(
        live_server, sim_process, ros_peer, sse_client):
    """The simulator relocalises as AMCL does (map -> odom moves, odometry's position does not jump):
    the scan, placed through map -> odom -> base_link -> base_scan, is on the walls at the new pose."""
    sim_process("--only", "rover")
    stream = sse_client(live_server.url + "/api/events?channels=scan")
    stream.wait_for("scan", lambda d: d["placed_by"] == "tf", timeout=30)
    peer = ros_peer("initial_pose_peer")
    peer.advertise("/initialpose", AMCL)
    peer.wait_match("/initialpose")
    x, y, yaw = 18.0, 10.5, 2.5   # the middle of the basement's corridor, facing west-north-west
    pose = {**amcl(x, y, yaw), "header": {"frame_id": "map"}}

    def moved():
        peer.publish("/initialpose", pose)
        odom = requests.get(live_server.url + "/api/tf/lookup", params={"target": "map", "source": "odom"},
                            timeout=5)
        return odom.ok and abs(odom.json()["translation"][0]) > 1.0 and odom.json()
    map_odom = wait_until(moved, timeout=15, interval=0.5, what="map -> odom moved by the initial pose")
    assert map_odom["yaw"] == pytest.approx(0.0, abs=1e-9)   # a position correction; odom stays map-aligned
    lx, ly, heading = laser_origin((x, y, yaw))
    scan = stream.wait_for("scan", lambda d: d["points"] and abs(d["pose"][0] - lx) < 0.01, timeout=15)["json"]
    assert scan["pose"][:2] == pytest.approx([lx, ly], abs=0.01) and scan["placed_by"] == "tf"
    assert math.cos(scan["pose"][2] - heading) == pytest.approx(1.0, abs=1e-4)
    assert LASER.frame == scan["frame_id"]
    assert on_walls(np.array(scan["points"]).reshape(-1, 2)) == 1.0
