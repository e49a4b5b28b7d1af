"""The e-stop with real ROS peers: /e_stop, zero velocity, goal cancels, and every motion path refused."""

import time

import requests

from tests.support.panels_support import (
    drone_sim,  # noqa: F401 (fixture)
    wait_display,
)
from tests.support.panels_support import post as panel_post
from tests.support.teleop_support import TeleopClient
from tests.support.waiting import wait_until

BOOL = "std_msgs/msg/Bool"
TWIST = "geometry_msgs/msg/Twist"
F64_ARRAY = "std_msgs/msg/Float64MultiArray"
POSE_STAMPED = "geometry_msgs/msg/PoseStamped"


def post(server, path, body):
    return requests.post(server.url + path, json=body, timeout=5)


def test_a_late_subscriber_gets_the_latch_and_sees_release(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_ESTOP_REPEAT_S=5.0)  # the latch, not the repeat, must deliver
    assert post(server, "/api/estop", {"engaged": True}).json()["engaged"] is True
    late = ros_peer("late_safety_node")
    late.subscribe("/e_stop", BOOL, qos="latched")
    assert late.wait_for("/e_stop", timeout=5)["msg"]["data"] is True
    late.clear("/e_stop")
    assert post(server, "/api/estop", {"engaged": False}).json()["engaged"] is False
    assert late.wait_for("/e_stop", lambda m: m["data"] is False, timeout=5)


def test_the_flag_is_republished_for_a_safety_node_that_missed_a_change(live_server_factory, ros_peer):
    listener = ros_peer("volatile_listener")
    server = live_server_factory(ROVER_WEB_ESTOP_REPEAT_S=0.2)
    listener.subscribe("/e_stop", BOOL)  # volatile: it only hears what is sent after it joined
    listener.wait_match("/e_stop")
    post(server, "/api/estop", {"engaged": True})
    wait_until(lambda: sum(e["msg"]["data"] for e in listener.received("/e_stop")) >= 4, timeout=5, what="repeats")


def test_zero_velocity_keeps_coming_while_engaged(live_server, ros_peer):
    peer = ros_peer("cmd_vel_listener")
    peer.subscribe("/cmd_vel", TWIST)
    peer.wait_match("/cmd_vel")
    post(live_server, "/api/estop", {"engaged": True})
    peer.wait_for("/cmd_vel", timeout=2)
    peer.clear("/cmd_vel")
    time.sleep(1.0)
    zeros = [e["msg"] for e in peer.received("/cmd_vel")]
    assert len(zeros) >= 10, len(zeros)  # at the teleop rate (40 Hz by default), at least 10 Hz
    assert all(m["linear"]["x"] == 0.0 and m["angular"]["z"] == 0.0 for m in zeros)
    post(live_server, "/api/estop", {"engaged": False})
    time.sleep(0.3)
    peer.clear("/cmd_vel")
    time.sleep(0.5)
    assert peer.received("/cmd_vel") == []  # released and idle: nothing more


def test_engaging_cancels_the_navigation_goal_at_once(live_server, action_server):
    nav = action_server("/navigate_to_pose")
    # As on a robot, where Nav2 runs long before anyone reaches for the e-stop: the app's cancel
    # client has found the server.
    wait_until(lambda: "/navigate_to_pose" in requests.get(live_server.url + "/api/estop", timeout=5).json()[
        "cancellable_actions"], what="the action server seen by the app")
    nav.send_goal()
    t0 = time.monotonic()
    state = post(live_server, "/api/estop", {"engaged": True}).json()
    canceled = nav.wait("canceled", timeout=5)
    # At once: the cancel goes out with the latch, not after it. The bound leaves room for a loaded
    # machine: tests assert no speed.
    assert canceled["t"] - t0 < 1.0, canceled["t"] - t0
    assert state["engaged"]
    outcome = wait_until(lambda: answered(live_server), what="the cancel outcome")
    by_action = {o["action"]: o for o in outcome}
    assert by_action["/navigate_to_pose"]["result"] == "canceled" and by_action["/navigate_to_pose"]["goals"] == 1
    assert by_action["/follow_waypoints"]["result"] == "not_running"


def answered(server) -> list[dict] | None:
    """The e-stop's cancel outcomes once every action has answered (a loaded machine's server may
    answer after the 1 s `no_answer`; its answer then replaces that)."""
    outcome = requests.get(server.url + "/api/estop", timeout=5).json()["cancel"]
    return None if not outcome or any(o["result"] == "no_answer" for o in outcome) else outcome


def test_a_cancel_answered_late_replaces_no_answer(live_server, action_server):
    nav = action_server("/navigate_to_pose", cancel_delay_s=2.0)  # answers 2 s after it is asked
    wait_until(lambda: "/navigate_to_pose" in requests.get(live_server.url + "/api/estop", timeout=5).json()[
        "cancellable_actions"], what="the action server seen by the app")
    nav.send_goal()
    post(live_server, "/api/estop", {"engaged": True})
    first = wait_until(lambda: requests.get(live_server.url + "/api/estop", timeout=5).json()["cancel"],
                       what="the first cancel outcome")
    assert {o["action"]: o["result"] for o in first}["/navigate_to_pose"] == "no_answer"  # 1 s passed first
    late = {o["action"]: o for o in wait_until(lambda: answered(live_server), what="the late answer")}
    assert (late["/navigate_to_pose"]["result"], late["/navigate_to_pose"]["goals"]) == ("canceled", 1)
    nav.wait("canceled", timeout=5)


def test_every_motion_request_is_refused_while_engaged_and_nothing_is_published(live_server, ros_peer):
    peer = ros_peer("motion_listener")
    for topic, kind in (("/waypoints", F64_ARRAY), ("/mission", F64_ARRAY), ("/goal_pose", POSE_STAMPED),
                        ("/control_phase", "std_msgs/msg/Int8")):
        peer.subscribe(topic, kind)
        peer.wait_match(topic)
    assert post(live_server, "/api/waypoints", {"lng": -71.0, "lat": 42.0}).status_code == 201
    peer.wait_for("/waypoints", timeout=5)
    assert post(live_server, "/api/panels/drone/unlock", {}).status_code == 200
    post(live_server, "/api/estop", {"engaged": True})
    time.sleep(0.3)
    for topic in ("/waypoints", "/mission", "/goal_pose", "/control_phase"):
        peer.clear(topic)
    maps = requests.get(live_server.url + "/api/maps", timeout=5).json()
    first_map = maps["maps"][0]["name"]
    refused = {
        "seed waypoint": post(live_server, "/waypoints", {"lng": -71.0, "lat": 42.0}),
        "mission add": post(live_server, "/api/waypoints", {"lng": -71.001, "lat": 42.001}),
        "mission send": post(live_server, "/api/waypoints/send", {}),
        "livemap goal": post(live_server, f"/api/maps/{first_map}/goal", {"x": 0.0, "y": 0.0}),
        "panel command": post(live_server, "/api/panels/drone/height", {"value": 10, "confirmed": True}),
        "teleop": post(live_server, "/api/teleop", {"command": "forward"}),
    }
    for what, response in refused.items():
        assert response.status_code == 409, (what, response.status_code, response.text)
        assert response.json()["error"] == "estop_engaged", what
    time.sleep(0.5)
    for topic in ("/waypoints", "/mission", "/goal_pose"):
        assert peer.received(topic) == [], topic
    assert peer.received("/control_phase") == []
    mission = requests.get(live_server.url + "/api/waypoints", timeout=5).json()
    assert len(mission["waypoints"]) == 1  # the refused adds changed nothing
    # Edits that publish nothing stay allowed, and so does the panel's Stop.
    waypoint_id = mission["waypoints"][0]["id"]
    assert requests.patch(live_server.url + f"/api/waypoints/{waypoint_id}", json={"label": "dock"},
                          timeout=5).status_code == 200
    assert post(live_server, "/api/panels/drone/stop", {}).status_code == 200
    assert peer.wait_for("/control_phase", timeout=5)["msg"]["data"] == 0


def test_the_simulated_drone_hovers_on_engage(live_server, drone_sim):  # noqa: F811
    drone_sim("--drone-transition-s", "0.5", "--drone-rate-hz", "10")
    url = live_server.url
    wait_display(url, "drone", "status", "Standby")
    assert panel_post(url, "drone/unlock").status_code == 200
    assert panel_post(url, "drone/takeoff", {"confirmed": True}).status_code == 200
    wait_display(url, "drone", "status", "Hovering")
    assert panel_post(url, "drone/destination", {"value": 7, "confirmed": True}).status_code == 200
    wait_display(url, "drone", "status", "Flying")
    post(live_server, "/api/estop", {"engaged": True})  # no unlock needed: the panel's on_estop
    wait_display(url, "drone", "status", "Hovering", timeout=5)
    log = requests.get(url + "/api/panels/drone/log", timeout=5).json()["entries"]
    assert log[0]["control"] == "stop" and log[0]["result"] == "sent" and "e-stop" in log[0]["reason"]


def test_estop_frame_on_the_teleop_socket_engages_from_any_session(live_server, ros_peer):
    viewer = TeleopClient(live_server.url, name="viewer")
    driver = TeleopClient(live_server.url, name="driver")
    driver.drive(0.5)
    viewer.send({"estop": True})
    state = viewer.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop")
    assert state["estop"] is True
    latch = requests.get(live_server.url + "/api/estop", timeout=5).json()
    assert latch["engaged"] and latch["by"] == "viewer" and latch["via"] == "websocket"
    driver.drive(0.5)
    assert driver.wait_for(lambda m: m["type"] == "error")["error"] == "estop_engaged"
    viewer.close(), driver.close()

