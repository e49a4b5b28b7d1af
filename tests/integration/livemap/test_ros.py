"""LiveMap with real ROS peers in other processes: pose, goal, plan, live OccupancyGrid, the simulator."""

import io
import math
import subprocess
import sys
import time
from urllib.parse import quote

import pytest
import requests
from PIL import Image

from tests.support.rospeer import ROOT, subprocess_env
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

BASEMENT = "Science Hall Basement"
B = quote(BASEMENT)
AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"
GOAL = "geometry_msgs/msg/PoseStamped"
PATH = "nav_msgs/msg/Path"
GRID = "nav_msgs/msg/OccupancyGrid"
TWIST = "geometry_msgs/msg/Twist"


def amcl(x, y, yaw=0.0, frame="map"):
    return {"header": {"frame_id": frame},
            "pose": {"pose": {"position": {"x": x, "y": y},
                              "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}}


def map_state(url, name=B, cm_per_pixel=None):
    query = f"?cm_per_pixel={cm_per_pixel}" if cm_per_pixel else ""
    return requests.get(f"{url}/api/maps/{name}{query}", timeout=5).json()


def test_a_latched_amcl_pose_shows_on_the_map_state_and_the_pose_channel(live_server_factory, ros_peer,
                                                                           sse_client):
    peer = ros_peer()
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    peer.publish("/amcl_pose", amcl(23.0, 4.0, math.pi / 2))  # before the app exists: transient local delivers it
    server = live_server_factory()
    state = wait_until(lambda: (s := map_state(server.url, cm_per_pixel=2))["map_parameters"]["current_pose"] and s,
                       what="the latched pose reached the app")
    pose = state["map_parameters"]["current_pose"]
    assert (pose["x"], pose["y"], pose["frame_id"], pose["stale"]) == (23.0, 4.0, "map", False)
    assert pose["yaw"] == pytest.approx(math.pi / 2)
    scaled = state["scaled_pixel_values"]["current_pose"]
    assert (scaled["x"], scaled["y"]) == pytest.approx((1250.0, 925.0))  # native (500, 370) at 2.5x
    assert scaled["inside"] is True
    stream = sse_client(server.url + "/api/events?channels=pose")
    first = stream.wait_for("pose")["json"]                                # the snapshot
    assert first["pixels"][BASEMENT] == {"x": 500.0, "y": 370.0, "yaw": pytest.approx(math.pi / 2, abs=1e-4),
                                         "inside": True}
    peer.publish("/amcl_pose", amcl(-5.0, 0.0, 0.0))                        # in the lab, off the basement
    event = stream.wait_for("pose", lambda d: d["x"] == -5.0)["json"]
    assert event["pixels"]["Robotics Lab"] == {"x": 40.0, "y": 180.0, "yaw": 0.0, "inside": True}
    assert event["pixels"][BASEMENT]["inside"] is False
    lab = map_state(server.url, quote("Robotics Lab"))["scaled_pixel_values"]["current_pose"]
    assert (lab["x"], lab["y"]) == pytest.approx((40.0, 180.0))


def test_the_pose_goes_stale_and_comes_back(live_server_factory, ros_peer, sse_client):
    server = live_server_factory(ROVER_WEB_LIVEMAP_POSE_STALE_S=0.5)
    peer = ros_peer()
    peer.advertise("/amcl_pose", AMCL, qos="latched")
    peer.wait_match("/amcl_pose")
    stream = sse_client(server.url + "/api/events?channels=pose")
    peer.publish("/amcl_pose", amcl(1.0, 1.0))
    stream.wait_for("pose", lambda d: d["x"] == 1.0 and not d["stale"])
    stale = stream.wait_for("pose", lambda d: d["stale"], timeout=5)["json"]
    assert stale["x"] == 1.0 and stale["age_s"] >= 0.5
    current = map_state(server.url)["map_parameters"]["current_pose"]
    assert current["stale"] is True and current["age_s"] >= 0.5
    peer.publish("/amcl_pose", amcl(1.5, 1.0))
    stream.wait_for("pose", lambda d: d["x"] == 1.5 and not d["stale"])


def test_goals_from_other_nodes_and_paths_are_shown(live_server, ros_peer, sse_client):
    peer = ros_peer()
    peer.advertise("/goal_pose", GOAL)
    peer.advertise("/plan", PATH)
    peer.wait_match("/goal_pose")
    peer.wait_match("/plan")
    stream = sse_client(live_server.url + "/api/events?channels=goal,plan")
    goal = {"header": {"frame_id": "map"}, "pose": {"position": {"x": 30.0, "y": 19.0}, "orientation": {"w": 1.0}}}
    wait_until(lambda: peer.publish("/goal_pose", goal) or stream.of("goal"), what="the goal channel")
    event = stream.wait_for("goal", lambda d: d["x"] == 30.0)["json"]
    assert event["frame_id"] == "map" and event["pixels"][BASEMENT]["x"] == 640.0
    poses = [{"pose": {"position": {"x": 2.0 + i * 0.01, "y": 10.5}, "orientation": {"w": 1.0}}} for i in range(2000)]
    plan = {"header": {"frame_id": "map"}, "poses": poses}
    wait_until(lambda: peer.publish("/plan", plan) or stream.of("plan"), timeout=15, interval=0.5, what="plan")
    event = stream.wait_for("plan", lambda d: d["length"] == 2000)["json"]
    assert len(event["points"]) == 500
    assert event["points"][0] == [2.0, 10.5] and event["points"][-1] == [21.99, 10.5]
    peer.publish("/plan", {"header": {"frame_id": "map"}, "poses": []})
    stream.wait_for("plan", lambda d: d["length"] == 0 and d["points"] == [])


def grid(width, height, origin=(-3.0, -2.0), resolution=0.1):
    cells = [-1] * (width * height)
    for col in range(width // 2):           # the left half of the bottom row is free...
        cells[col] = 0
    cells[width // 2] = 100                 # ...then one wall cell
    cells[(height - 1) * width + width - 1] = 100   # and the top-right cell is occupied
    return {"header": {"frame_id": "map"},
            "info": {"width": width, "height": height, "resolution": resolution,
                     "origin": {"position": {"x": origin[0], "y": origin[1]}, "orientation": {"w": 1.0}}},
            "data": cells}


def test_a_live_occupancy_grid_becomes_a_map_image(live_server_factory, ros_peer, sse_client):
    peer = ros_peer()
    peer.advertise("/map", GRID, qos="latched")
    peer.publish("/map", grid(60, 40))
    server = live_server_factory(ROVER_WEB_LIVEMAP_MAP_TOPIC="/map")
    stream = sse_client(server.url + "/api/events?channels=live_map")
    live = wait_until(lambda: next((m for m in requests.get(server.url + "/api/maps", timeout=5).json()["maps"]
                                    if m["source"] == "live"), None), what="the live map")
    assert live["name"] == "live map" and live["label"] == "live /map"
    assert (live["width_px"], live["height_px"]) == (60, 40)
    assert live["resolution_m"] == pytest.approx(0.1) and live["origin"][:2] == pytest.approx([-3.0, -2.0])
    response = requests.get(server.url + live["urls"]["image"], timeout=5)
    assert response.headers["Content-Type"] == "image/png"
    with Image.open(io.BytesIO(response.content)) as image:
        assert image.size == (60, 40)
        free, wall, unknown = image.getpixel((0, 39)), image.getpixel((30, 39)), image.getpixel((10, 10))
        corner = image.getpixel((59, 0))
    assert len({free, wall, unknown}) == 3, (free, wall, unknown)
    assert free > unknown > wall and corner == wall
    state = map_state(server.url, quote("live map"))
    assert state["map_parameters"]["source"] == "live"
    assert state["map_parameters"]["files"]["png"]["pixel_width"] == 60
    stream.wait_for("live_map", lambda d: d["width_px"] == 60)
    # SLAM grows the map: a new grid replaces the old one under the same name.
    peer.publish("/map", grid(80, 50, origin=(-4.0, -2.0)))
    event = stream.wait_for("live_map", lambda d: d["width_px"] == 80)["json"]
    assert event["version"] == live["version"] + 1
    png = requests.get(f"{server.url}/api/maps/{quote('live map')}/image", timeout=5).content
    with Image.open(io.BytesIO(png)) as image:
        assert image.size == (80, 50)
    ok = requests.post(f"{server.url}/api/maps/{quote('live map')}/goal", json={"x": 3.9, "y": 2.9}, timeout=5)
    assert ok.status_code == 200
    outside = requests.post(f"{server.url}/api/maps/{quote('live map')}/goal", json={"x": 4.1, "y": 0.0}, timeout=5)
    assert outside.status_code == 400 and outside.json()["error"] == "outside_map"


def test_without_a_map_topic_there_is_no_live_map(client):
    assert all(m["source"] == "file" for m in client.get("/api/maps").json["maps"])
    assert client.get(f"/api/maps/{quote('live map')}").status_code == 404


# --- the simulator ---


def sim_pose(url):
    pose = map_state(url)["map_parameters"]["current_pose"]
    return pose or None


def test_the_simulator_starts_in_the_basement_and_drives_to_a_goal_from_the_api(live_server, sim_process,
                                                                                 sse_client):
    sim_process()
    start = wait_until(lambda: sim_pose(live_server.url), timeout=20, what="the simulator's pose")
    assert (start["x"], start["y"]) == pytest.approx((2.0, 10.5), abs=0.01)   # the basement's Dock
    stream = sse_client(live_server.url + "/api/events?channels=plan,pose")
    goal = {"x": 4.5, "y": 10.5, "yaw": math.pi / 2}
    wait_until(lambda: requests.post(f"{live_server.url}/api/maps/{B}/goal", json=goal, timeout=5).ok
               and (p := sim_pose(live_server.url)) and p["x"] > 2.05, timeout=20, interval=0.5,
               what="the simulator started moving")
    stream.wait_for("plan", lambda d: d["length"] > 1 and d["points"][-1] == [4.5, 10.5])

    def arrived():
        p = sim_pose(live_server.url)
        return p if math.hypot(p["x"] - 4.5, p["y"] - 10.5) < 0.1 and abs(p["yaw"] - math.pi / 2) < 0.1 else None

    there = wait_until(arrived, timeout=30, interval=0.2, what="the simulator reached the goal")
    stream.wait_for("plan", lambda d: d["length"] == 0)   # its path is cleared on arrival
    time.sleep(1.0)
    still = sim_pose(live_server.url)
    assert math.hypot(still["x"] - there["x"], still["y"] - there["y"]) < 0.02   # and it stopped there
    pixels = stream.wait_for("pose", lambda d: abs(d["x"] - still["x"]) < 0.02)["json"]["pixels"][BASEMENT]
    assert pixels["x"] == pytest.approx((still["x"] + 2.0) / 0.05, abs=0.5)


def test_an_operator_command_cancels_the_simulator_s_goal(live_server, sim_process, ros_peer):
    sim_process("--start", "2.0", "10.5", "0.0")
    peer = ros_peer()
    peer.advertise("/cmd_vel", TWIST)
    peer.wait_match("/cmd_vel")
    wait_until(lambda: sim_pose(live_server.url), timeout=20, what="the simulator's pose")
    wait_until(lambda: requests.post(f"{live_server.url}/api/maps/{B}/goal", json={"x": 30.0, "y": 10.5},
                                     timeout=5).ok and sim_pose(live_server.url)["x"] > 2.3,
               timeout=20, interval=0.5, what="the simulator started moving")
    peer.publish("/cmd_vel", {})   # a stop from the operator
    time.sleep(1.0)                 # the base's own 0.5 s command timeout has passed too
    halted = sim_pose(live_server.url)
    time.sleep(1.5)
    later = sim_pose(live_server.url)
    assert later["x"] < 10.0 and abs(later["x"] - halted["x"]) < 0.02, (halted, later)


def test_a_bad_maps_file_stops_the_server_with_one_sentence_naming_file_and_key(tmp_path):
    bad = tmp_path / "all_maps.json"
    bad.write_text('{"Hall": {"files": {"path": "", "png_file": {"file_name": "../etc/x.png"}}}}')
    result = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload", "--port", "1"],
                            cwd=ROOT, env=subprocess_env(ROVER_WEB_MAPS_FILE=str(bad)), capture_output=True,
                            text=True, timeout=30)
    assert result.returncode != 0
    last_line = result.stderr.strip().splitlines()[-1]
    assert last_line.startswith(f"rover_web: {bad}: \"Hall\".files.png_file.file_name:"), result.stderr
    assert "Traceback" not in result.stderr
