"""Nav2's actions driven through the REST API against the simulator in another process, which
answers them as Nav2 does: goals around the walls with feedback, routes, unreachable goals with
Nav2's error codes, cancel by the operator, the e-stop and revocation, the keep-out areas."""

import math
import os
import signal
import subprocess
import sys
import threading
import time

import pytest
import requests

from rover_web.config import ROOT
from rover_web.livemap.map_files import load_catalog, maps_file_path
from rover_web.sim.rover import default_start
from rover_web.sim.walls import Walls
from tests.support.auth import bearer
from tests.support.rospeer import subprocess_env
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

nav2_msgs = pytest.importorskip("nav2_msgs.action", reason="nav2_msgs is built by scripts/build_interfaces.sh")


def state(server, headers=None) -> dict:
    return requests.get(server.url + "/api/nav2", headers=headers, timeout=5).json()


def ready(server, headers=None) -> dict:
    """Nav2's servers (the simulator's) found and their lifecycle states read."""
    return wait_until(lambda: (s := state(server, headers))["servers"]["to_pose"]["ready"]
                      and all(n["state"] == "active" for n in s["lifecycle"]) and s, 30,
                      "the simulator's Nav2 servers, active")


def result_of(server, goal_id, timeout=60.0, headers=None) -> dict:
    return wait_until(lambda: (s := state(server, headers))["goal"]["id"] == goal_id and s["result"] and s,
                      timeout, "the goal's result", interval=0.2)


def pose(server) -> dict:
    return requests.get(server.url + "/api/maps/Science%20Hall%20Basement", timeout=5).json()[
        "map_parameters"]["current_pose"]


def blocked_point() -> tuple[float, float]:
    """A point the robot cannot stand on: inside a wall near the start (the wall grid the simulator uses)."""
    definition = next(iter(load_catalog(maps_file_path("map_files/all_maps.json")).values()))
    walls = Walls.of_map(definition)
    x0, y0, _ = default_start()
    for step in range(1, 200):
        y = y0 + step * 0.05
        if walls.is_blocked(x0, y) and walls.is_blocked(x0, y + 0.1) and walls.is_blocked(x0, y - 0.05):
            return x0, y
    raise AssertionError("no wall north of the start")


def test_a_goal_is_driven_around_the_walls_with_feedback_to_success(live_server, sim_process, sse_client):
    sim_process("--only", "rover", "--goal-speed", "2.0")
    node = live_server.rover.runtime.node

    def main_node_entities():
        return len(list(node.clients)), len(list(node.waitables)), len(list(node.subscriptions))

    before = main_node_entities()  # before the first look, which makes the Nav2 clients' own node
    first = ready(live_server)
    assert first["available"] and first["missing"] is None
    assert first["goal_via"] == "action"  # auto: the server is there
    assert {n["node"] for n in first["lifecycle"]} >= {"/bt_navigator", "/planner_server", "/controller_server"}
    events = sse_client(live_server.url + "/api/events?channels=nav2")
    # Lab B12 from the Dock: around a room's walls, not through them
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": 23.0, "y": 4.0, "yaw": 0.0}, timeout=10)
    assert reply.status_code == 200, reply.text
    goal = reply.json()["goal"]
    assert goal["kind"] == "to_pose" and goal["action"] == "/navigate_to_pose"
    assert goal["map"] == "Science Hall Basement" and goal["poses"] == [{"x": 23.0, "y": 4.0, "yaw": 0.0}]
    seen = wait_until(lambda: (s := state(live_server))["feedback"] and s, 10, "feedback")
    feedback = seen["feedback"]
    # The path around the walls is longer than the straight line (21.3 m)
    x0, y0, _ = default_start()
    assert feedback["distance_remaining_m"] > math.hypot(23.0 - x0, 4.0 - y0) + 1.0
    assert feedback["estimated_time_remaining_s"] > 0 and feedback["number_of_recoveries"] == 0
    done = result_of(live_server, goal["id"], 90)
    assert done["result"]["status"] == "succeeded", done
    assert done["result"]["error_code"] == 0 and done["goal"]["status"] == "succeeded"
    at = pose(live_server)
    assert math.hypot(at["x"] - 23.0, at["y"] - 4.0) < 0.1
    # The channel carried feedback at a bounded rate (5 a second by default), and ended on the result.
    frames = events.of("nav2")
    with_feedback = [f for f in frames if f["json"]["feedback"]]
    assert len(with_feedback) >= 5
    span = with_feedback[-1]["t"] - with_feedback[0]["t"]
    assert len(with_feedback) <= span * 5 + 2  # the simulator sends 20 a second
    wait_until(lambda: events.of("nav2")[-1]["json"]["result"], 5, "the result on the nav2 channel")
    # The action and GetState clients are on their own node: the main executor's wait set is untouched.
    assert main_node_entities() == before


def test_an_unreachable_goal_ends_aborted_with_nav2s_error_code(live_server, sim_process):
    sim_process("--only", "rover")
    ready(live_server)
    x, y = blocked_point()
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": x, "y": y}, timeout=10)
    assert reply.status_code == 200, reply.text  # Nav2 accepts, then its planner fails
    done = result_of(live_server, reply.json()["goal"]["id"])
    result = done["result"]
    assert result["status"] == "aborted"
    assert result["error_code"] == 206 and result["error_name"] == "GOAL_OCCUPIED"
    assert "wall" in result["error_msg"]
    # Behind the walls with no door: no path
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": 37.0, "y": 10.5}, timeout=10)
    result = result_of(live_server, reply.json()["goal"]["id"])["result"]
    assert (result["status"], result["error_code"], result["error_name"]) == ("aborted", 208, "NO_VALID_PATH")


def test_a_route_of_waypoints_is_followed_to_each_point(live_server, sim_process, ros_peer):
    sim_process("--only", "rover", "--goal-speed", "2.0")
    peer = ros_peer()
    peer.subscribe("/amcl_pose", "geometry_msgs/msg/PoseWithCovarianceStamped", qos="latched", max_items=5000)
    ready(live_server)
    points = [(3.5, 15.0), (4.0, 8.0)]  # Storage, then back down the corridor
    reply = requests.post(live_server.url + "/api/nav2/route", timeout=10, json={
        "mode": "follow_waypoints", "poses": [{"x": x, "y": y} for x, y in points]})
    assert reply.status_code == 200, reply.text
    goal = reply.json()["goal"]
    assert goal["kind"] == "follow_waypoints" and goal["action"] == "/follow_waypoints"
    current = set()

    def finished():
        s = state(live_server)
        if s["feedback"]:
            current.add(s["feedback"]["current_waypoint"])
        return s["result"] and s

    done = wait_until(finished, 90, "the route's result", interval=0.2)
    assert done["result"]["status"] == "succeeded" and done["result"]["missed_waypoints"] == []
    assert current == {0, 1}
    trail = [(m["msg"]["pose"]["pose"]["position"]["x"], m["msg"]["pose"]["pose"]["position"]["y"])
             for m in peer.received("/amcl_pose")]
    for x, y in points:  # it stopped at each (amcl_pose at 10 Hz: within a few cm)
        assert min(math.hypot(px - x, py - y) for px, py in trail) < 0.08, (x, y)


def test_a_route_through_poses_with_a_missed_waypoint_and_the_keep_out_refusal(live_server, sim_process):
    sim_process("--only", "rover", "--goal-speed", "2.0")
    ready(live_server)
    # The electrical room is a keep-out area of the basement: refused before anything is sent
    reply = requests.post(live_server.url + "/api/nav2/route", timeout=10, json={
        "mode": "through_poses", "poses": [{"x": 4.0, "y": 8.0}, {"x": 35.0, "y": 2.0}]})
    assert reply.status_code == 422
    body = reply.json()
    assert body["error"] == "outside_geofence" and body["reason"] == "inside_keep_out" and body["index"] == 1
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": 35.0, "y": 2.0}, timeout=10)
    assert reply.status_code == 422 and reply.json()["name"] == "electrical room"
    assert state(live_server)["goal"] is None  # nothing was sent
    # FollowWaypoints skips a waypoint it cannot reach and reports it with the planner's code
    reply = requests.post(live_server.url + "/api/nav2/route", timeout=10, json={
        "mode": "follow_waypoints", "poses": [{"x": 37.0, "y": 10.5}, {"x": 3.0, "y": 10.5}]})
    done = result_of(live_server, reply.json()["goal"]["id"], 60)
    result = done["result"]
    assert result["status"] == "succeeded"
    assert [(m["index"], m["error_code"], m["error_name"]) for m in result["missed_waypoints"]] == [
        (0, 208, "NO_VALID_PATH")]
    # NavigateThroughPoses drives through both and reports the poses left
    reply = requests.post(live_server.url + "/api/nav2/route", timeout=10, json={
        "mode": "through_poses", "poses": [{"x": 4.0, "y": 8.0}, {"x": 4.0, "y": 5.0}]})
    assert reply.status_code == 200
    left = wait_until(lambda: (s := state(live_server))["feedback"] and s["feedback"], 10, "feedback")
    assert left["number_of_poses_remaining"] in (1, 2)
    done = result_of(live_server, reply.json()["goal"]["id"], 60)
    assert done["result"]["status"] == "succeeded"
    at = pose(live_server)
    assert math.hypot(at["x"] - 4.0, at["y"] - 5.0) < 0.1


def test_the_operator_cancels_and_the_robot_stops(live_server, sim_process):
    sim_process("--only", "rover")
    ready(live_server)
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": 23.0, "y": 4.0}, timeout=10)
    goal_id = reply.json()["goal"]["id"]
    wait_until(lambda: state(live_server)["feedback"], 10, "feedback")
    time.sleep(0.5)
    canceled = requests.post(live_server.url + "/api/nav2/cancel", json={}, timeout=10)
    assert canceled.status_code == 200 and canceled.json()["goal"]["cancel"]["by"] == "operator"
    done = result_of(live_server, goal_id)
    assert done["result"]["status"] == "canceled" and done["goal"]["cancel"]["answer"] in ("canceling", None)
    still = pose(live_server)
    time.sleep(1.0)
    after = pose(live_server)
    assert math.hypot(after["x"] - still["x"], after["y"] - still["y"]) < 0.05
    again = requests.post(live_server.url + "/api/nav2/cancel", json={}, timeout=10)
    assert again.status_code == 409 and again.json()["error"] == "no_goal"


def test_the_estop_cancels_a_running_goal_and_refuses_new_ones(live_server, sim_process):
    sim_process("--only", "rover")
    ready(live_server)
    reply = requests.post(live_server.url + "/api/nav2/goal", json={"x": 23.0, "y": 4.0}, timeout=10)
    goal_id = reply.json()["goal"]["id"]
    wait_until(lambda: (f := state(live_server)["feedback"]) and f["navigation_time_s"] > 0.5, 10, "driving")
    assert requests.post(live_server.url + "/api/estop", json={"engaged": True}, timeout=5).ok
    done = result_of(live_server, goal_id)
    assert done["result"]["status"] == "canceled"
    assert done["goal"]["cancel"]["by"] == "e-stop"
    estop = requests.get(live_server.url + "/api/estop", timeout=5).json()
    assert {"action": "/navigate_to_pose", "result": "canceled", "goals": 1} in estop["cancel"] or any(
        c["action"] == "/navigate_to_pose" for c in estop["cancel"] or [])
    refused = requests.post(live_server.url + "/api/nav2/goal", json={"x": 4.0, "y": 5.0}, timeout=10)
    assert refused.status_code == 409 and refused.json()["error"] == "estop_engaged"
    refused = requests.post(live_server.url + "/api/nav2/route", json={"mode": "follow_waypoints",
                                                                       "poses": [{"x": 4.0, "y": 5.0}]}, timeout=10)
    assert refused.status_code == 409
    still = pose(live_server)
    time.sleep(1.0)
    after = pose(live_server)
    assert math.hypot(after["x"] - still["x"], after["y"] - still["y"]) < 0.05


def test_a_revoked_token_cancels_the_goal_it_sent(signed_server, sim_process):
    sim_process("--only", "rover")
    admin, operator = bearer(signed_server, "admin"), bearer(signed_server, "operator")
    ready(signed_server, admin)
    viewer = requests.post(signed_server.url + "/api/nav2/goal", json={"x": 23.0, "y": 4.0},
                           headers=bearer(signed_server, "viewer"), timeout=10)
    assert viewer.status_code == 403
    reply = requests.post(signed_server.url + "/api/nav2/goal", json={"x": 23.0, "y": 4.0}, headers=operator,
                          timeout=10)
    assert reply.status_code == 200, reply.text
    goal = reply.json()["goal"]
    assert goal["sent_by"] == "operator"
    wait_until(lambda: state(signed_server, admin)["feedback"], 10, "feedback")
    tokens = requests.get(signed_server.url + "/api/tokens", headers=admin, timeout=5).json()["tokens"]
    token_id = next(t["id"] for t in tokens if t["user"] == "operator")
    assert requests.delete(f"{signed_server.url}/api/tokens/{token_id}", headers=admin, timeout=5).ok
    done = result_of(signed_server, goal["id"], headers=admin)
    assert done["result"]["status"] == "canceled"
    assert done["goal"]["cancel"]["by"] == "revocation" and "revoked" in done["goal"]["cancel"]["reason"]


def test_the_simulator_runs_without_nav2_msgs_and_says_why(tmp_path, ros_peer):
    hidden = tmp_path / "hide" / "nav2_msgs"
    hidden.mkdir(parents=True)
    (hidden / "__init__.py").write_text('raise ImportError("nav2_msgs is hidden by this test")\n')
    sim = subprocess.Popen([sys.executable, "-m", "rover_web.sim", "--only", "rover"], cwd=ROOT, text=True,
                           env=subprocess_env(PYTHONPATH=f"{hidden.parent}{os.pathsep}{ROOT}"),
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    lines: list[str] = []
    reader = threading.Thread(target=lambda: lines.extend(sim.stdout), daemon=True)
    reader.start()
    try:
        peer = ros_peer()
        peer.subscribe("/odom", "nav_msgs/msg/Odometry", qos="sensor_data")
        peer.wait_for("/odom", timeout=20)  # the robot runs
        wait_until(lambda: any("nav2_msgs is not installed: no Nav2 actions" in line for line in lines), 10,
                   "the simulator's warning")
        assert any("simulator running" in line for line in lines)
    finally:
        sim.send_signal(signal.SIGINT)
        try:
            sim.wait(10)
        except subprocess.TimeoutExpired:
            sim.kill()
            sim.wait(5)
        reader.join(5)
        sim.stdout.close()
