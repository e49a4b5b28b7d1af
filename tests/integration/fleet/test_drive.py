"""Issue 20, safety per robot with a real ROS peer: driving one robot publishes on its cmd_vel only,
its e-stop leaves the other drivable, and POST /api/estop/all stops both."""

import time

import pytest

from tests.support.teleop_support import Stick, TeleopClient, is_zero, twists
from tests.support.waiting import wait_until

from .helpers import CMD_VEL, NAMES, ROOT_CMD_VEL, get, post

pytestmark = pytest.mark.ros

BOOL = "std_msgs/msg/Bool"
E_STOP = {name: f"/{name}/e_stop" for name in NAMES}
SETTLE_S = 0.3  # before saying nothing arrived: as long as a wrongly sent message would take


def moving(value: float):
    return lambda m: m["linear"]["x"] == pytest.approx(value)


def subscribe_latches(peer) -> None:
    for topic in E_STOP.values():
        peer.subscribe(topic, BOOL, qos="latched")
        peer.wait_match(topic)


def latch_on_ros(peer, name: str) -> bool:
    """The newest /<name>/e_stop the peer heard (the latch delivers the current one on subscribe)."""
    peer.wait_for(E_STOP[name], timeout=5)
    return peer.received(E_STOP[name])[-1]["msg"]["data"]


def drive_refused(url: str) -> None:
    response = post(url + "/api/teleop", {"command": "forward", "speed": 0.5})
    assert response.status_code == 409, response.text
    assert response.json()["error"] == "estop_engaged"


def test_driving_the_boat_publishes_on_the_boat_s_cmd_vel_only(drive_rig):
    server, peer = drive_rig()
    boat, drone = server.robot["boat"], server.robot["drone"]

    # REST: 0.5 of the 5 m/s maximum for half a second, then zero by itself.
    response = post(boat + "/api/teleop", {"command": "forward", "speed": 0.5, "duration_s": 0.5})
    assert response.status_code == 200 and response.json()["linear_mps"] == 2.5
    peer.wait_for(CMD_VEL["boat"], moving(2.5), timeout=2)
    peer.wait_for(CMD_VEL["boat"], is_zero, timeout=2)

    # The WebSocket: a stick held at 0.4 on the boat's socket, then let go (the socket closes).
    peer.clear(CMD_VEL["boat"])
    stick = Stick(boat, name="alice", value=0.4)
    try:
        peer.wait_for(CMD_VEL["boat"], moving(2.0), timeout=2)
        robots = {r["name"]: r for r in get(server.url + "/api/robots")["robots"]}
        assert (robots["boat"]["mode"], robots["boat"]["operator"]) == ("driving", "alice")
        assert (robots["drone"]["mode"], robots["drone"]["operator"]) == ("idle", None)
        assert get(drone + "/api/teleop")["holder"] is None
    finally:
        stick.close()
    peer.wait_for(CMD_VEL["boat"], is_zero, timeout=2)
    time.sleep(SETTLE_S)
    assert peer.received(CMD_VEL["drone"]) == []
    assert peer.received(ROOT_CMD_VEL) == []


def test_the_boat_s_estop_leaves_the_drone_drivable(drive_rig):
    server, peer = drive_rig()
    boat, drone = server.robot["boat"], server.robot["drone"]
    subscribe_latches(peer)
    assert latch_on_ros(peer, "boat") is False and latch_on_ros(peer, "drone") is False

    engaged = post(boat + "/api/estop", {"engaged": True, "by": "deckhand"})
    assert engaged.status_code == 200 and engaged.json()["engaged"] is True
    peer.wait_for(E_STOP["boat"], lambda m: m["data"] is True, timeout=5)
    assert get(boat + "/api/estop")["engaged"] is True
    assert get(drone + "/api/estop")["engaged"] is False

    # The boat refuses REST and the socket alike.
    drive_refused(boat)
    boat_socket = TeleopClient(boat, name="alice")
    assert boat_socket.hello["estop"] is True
    boat_socket.drive(0.5)
    assert boat_socket.wait_for(lambda m: m["type"] == "error")["error"] == "estop_engaged"
    boat_socket.close()

    # The drone drives, by REST and by its socket, on its own topic.
    peer.clear(CMD_VEL["drone"])
    response = post(drone + "/api/teleop", {"command": "forward", "speed": 0.5, "duration_s": 0.5})
    assert response.status_code == 200, response.text
    peer.wait_for(CMD_VEL["drone"], moving(2.5), timeout=2)
    peer.wait_for(CMD_VEL["drone"], is_zero, timeout=2)
    stick = Stick(drone, name="pilot", value=0.4)
    try:
        peer.wait_for(CMD_VEL["drone"], moving(2.0), timeout=2)
    finally:
        stick.close()

    # Meanwhile the boat got nothing but the e-stop's zeros, and the drone's latch stayed off.
    assert twists(peer, CMD_VEL["boat"]), "the engaged boat's zero velocity is held on its topic"
    assert all(lin == 0.0 and ang == 0.0 for _, lin, ang in twists(peer, CMD_VEL["boat"]))
    assert all(e["msg"]["data"] is False for e in peer.received(E_STOP["drone"]))
    assert latch_on_ros(peer, "boat") is True
    assert peer.received(ROOT_CMD_VEL) == []


def test_estop_all_stops_both_and_each_is_released_on_its_own(drive_rig):
    server, peer = drive_rig(ROVER_WEB_ESTOP_REPEAT_S=0.2)
    boat, drone = server.robot["boat"], server.robot["drone"]
    subscribe_latches(peer)

    # The drone is driven from a held stick, the boat by a REST command that would last 5 s.
    stick = Stick(drone, name="pilot", value=0.4)
    try:
        peer.wait_for(CMD_VEL["drone"], moving(2.0), timeout=2)
        assert post(boat + "/api/teleop", {"command": "forward", "speed": 0.5, "duration_s": 5}).status_code == 200
        peer.wait_for(CMD_VEL["boat"], moving(2.5), timeout=2)

        response = post(server.url + "/api/estop/all", {"by": "chief"})
        assert response.status_code == 200, response.text
        body = response.json()
        assert body["engaged"] is True and set(body["robots"]) == {"boat", "drone"}
        assert all(latch["engaged"] and latch["by"] == "chief" for latch in body["robots"].values())
        zeros = {name: peer.wait_for(CMD_VEL[name], is_zero, timeout=2) for name in NAMES}
        for name in NAMES:
            peer.wait_for(E_STOP[name], lambda m: m["data"] is True, timeout=5)
            assert get(server.robot[name] + "/api/estop")["engaged"] is True
            drive_refused(server.robot[name])

        # The drone's socket is told, and the stick it still holds is refused frame after frame.
        stick.client.wait_for(lambda m: m["type"] == "state" and m["reason"] == "estop")
        stick.client.wait_errors(3)
        assert {e["error"] for e in stick.client.errors()} == {"estop_engaged"}
        robots = {r["name"]: r for r in get(server.url + "/api/robots")["robots"]}
        assert robots["boat"]["mode"] == robots["drone"]["mode"] == "estop"
    finally:
        stick.close()
    for name in NAMES:
        after = [(lin, ang) for t, lin, ang in twists(peer, CMD_VEL[name]) if t >= zeros[name]["t"]]
        assert after and all(v == (0.0, 0.0) for v in after), (name, after)

    # Releasing the drone leaves the boat engaged.
    released = post(drone + "/api/estop", {"engaged": False})
    assert released.status_code == 200 and released.json()["engaged"] is False
    peer.wait_for(E_STOP["drone"], lambda m: m["data"] is False, timeout=5)
    assert get(boat + "/api/estop")["engaged"] is True
    peer.clear(E_STOP["boat"])
    assert peer.wait_for(E_STOP["boat"], timeout=5)["msg"]["data"] is True  # republished: still engaged
    drive_refused(boat)
    peer.clear(CMD_VEL["drone"])
    # The stick's socket may still be closing on the server; then the drone is not yet free for REST.
    wait_until(lambda: post(drone + "/api/teleop", {"command": "left", "duration_s": 0.5}).status_code == 200,
               timeout=5, what="the released drone takes a REST command")
    peer.wait_for(CMD_VEL["drone"], lambda m: m["angular"]["z"] == pytest.approx(0.4), timeout=2)
    assert peer.received(ROOT_CMD_VEL) == []


def cancel_outcome(url: str) -> dict[str, dict]:
    """The e-stop's cancel outcomes by action, once every action has answered (on a loaded machine
    an answer can come after the 1 s `no_answer`, and then replaces it)."""
    outcome = get(url + "/api/estop")["cancel"]
    if not outcome or any(o["result"] == "no_answer" for o in outcome):
        return None
    return {o["action"]: o for o in outcome}


def test_a_robot_s_estop_cancels_its_own_navigation_goal_only(fleet_server, action_server):
    server = fleet_server()
    nav = {name: action_server(f"/{name}/navigate_to_pose") for name in NAMES}
    for name in NAMES:  # as on a robot, the app's cancel client found the server long before
        wait_until(lambda name=name: f"/{name}/navigate_to_pose" in get(server.robot[name] + "/api/estop")[
            "cancellable_actions"], what=f"the {name}'s action server seen by the app")
        nav[name].send_goal()

    assert post(server.robot["boat"] + "/api/estop", {"engaged": True}).status_code == 200
    nav["boat"].wait("canceled", timeout=5)
    # 20 s: a loaded machine's answer may come long after the server canceled (CI once waited 10 s in vain).
    boat = wait_until(lambda: cancel_outcome(server.robot["boat"]), timeout=20, what="the boat's cancel outcome")
    assert (boat["/boat/navigate_to_pose"]["result"], boat["/boat/navigate_to_pose"]["goals"]) == ("canceled", 1)
    assert "/drone/navigate_to_pose" not in boat

    # The drone's goal was left running: its own e-stop still finds it to cancel.
    assert post(server.robot["drone"] + "/api/estop", {"engaged": True}).status_code == 200
    nav["drone"].wait("canceled", timeout=5)
    drone = wait_until(lambda: cancel_outcome(server.robot["drone"]), timeout=20, what="the drone's cancel outcome")
    assert (drone["/drone/navigate_to_pose"]["result"], drone["/drone/navigate_to_pose"]["goals"]) == ("canceled", 1)
