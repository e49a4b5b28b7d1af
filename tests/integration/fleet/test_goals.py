"""Issue 20: goals and waypoints go to the right robot's namespace, heard by a real ROS peer; each
robot keeps its own mission, in its own database file."""

import time
from urllib.parse import quote

import pytest

from tests.support.waiting import wait_until
from tests.support.waypoint_helpers import FLOAT64_MULTI_ARRAY, stored_rows, warm_up_topic

from .helpers import NAMES, get, post

pytestmark = pytest.mark.ros

GOAL = "geometry_msgs/msg/PoseStamped"
SETTLE_S = 0.3  # before saying nothing arrived: as long as a wrongly sent message would take


def listen(peer, type_name: str, leaf: str) -> dict[str, str]:
    """Subscribe /boat/<leaf>, /drone/<leaf> and /<leaf>; wait until each robot's publisher matched,
    so a message sent to the wrong robot would be heard."""
    topics = {name: f"/{name}/{leaf}" for name in NAMES} | {"root": f"/{leaf}"}
    for topic in topics.values():
        peer.subscribe(topic, type_name, qos=100)
    for name in NAMES:
        peer.wait_match(topics[name])
    return topics


def lng_lat(peer, topic: str) -> list[list[float]]:
    return [event["msg"]["data"] for event in peer.received(topic)]


def test_waypoints_go_to_their_robot_s_topic_and_list(fleet_server, ros_peer, tmp_path):
    server = fleet_server(ROVER_WEB_DB_PATH=str(tmp_path / "fleet.sqlite3"))
    boat, drone = server.robot["boat"], server.robot["drone"]
    peer = ros_peer("waypoint_listener")
    topics = listen(peer, FLOAT64_MULTI_ARRAY, "waypoints")
    warm_up_topic(drone, peer, topics["drone"])
    warm_up_topic(boat, peer, topics["boat"])
    peer.clear(topics["drone"])

    added = post(drone + "/api/waypoints", {"lng": -82.451, "lat": 27.371, "label": "pad"})
    assert added.status_code == 201, added.text
    seed = post(drone + "/waypoints", {"lng": -82.452, "lat": 27.372})  # the seeds' call, under the prefix
    assert seed.status_code == 200 and seed.json()["status"] == "success"
    wait_until(lambda: len(peer.received(topics["drone"])) == 2, timeout=5, what="both drone waypoints heard")
    assert lng_lat(peer, topics["drone"]) == [[-82.451, 27.371], [-82.452, 27.372]]  # [lng, lat]

    assert post(boat + "/api/waypoints", {"lng": 10.5, "lat": 59.9}).status_code == 201
    assert peer.wait_for(topics["boat"], timeout=5)["msg"]["data"] == [10.5, 59.9]
    time.sleep(SETTLE_S)
    assert lng_lat(peer, topics["boat"]) == [[10.5, 59.9]]  # none of the drone's
    assert lng_lat(peer, topics["drone"]) == [[-82.451, 27.371], [-82.452, 27.372]]  # none of the boat's
    assert peer.received(topics["root"]) == []

    # Each robot lists its own mission; the root routes are the first robot's (the boat).
    def mission(url):
        return [(w["lng"], w["lat"]) for w in get(url + "/api/waypoints")["waypoints"]]

    assert mission(drone) == [(-82.451, 27.371), (-82.452, 27.372)]
    assert mission(boat) == [(10.5, 59.9)]
    assert mission(server.url) == mission(boat)

    # Sending the drone's mission publishes it on /drone/mission (until heard once: discovery).
    missions = listen(peer, FLOAT64_MULTI_ARRAY, "mission")
    wait_until(lambda: post(drone + "/api/waypoints/send").ok and peer.received(missions["drone"]), timeout=15,
               interval=0.1, what="the drone's mission heard")
    sent = peer.received(missions["drone"])[0]["msg"]
    assert sent["data"] == [-82.451, 27.371, -82.452, 27.372]
    time.sleep(SETTLE_S)
    assert peer.received(missions["boat"]) == [] and peer.received(missions["root"]) == []

    # ... kept in its own database file: the first robot's is ROVER_WEB_DB_PATH, the drone's beside it.
    boat_db, drone_db = tmp_path / "fleet.sqlite3", tmp_path / "fleet-drone.sqlite3"
    wait_until(lambda: len(stored_rows(drone_db)) == 2, timeout=5, what="the drone's waypoints stored")
    assert [row[1:] for row in stored_rows(drone_db)] == [(-82.451, 27.371, "pad"), (-82.452, 27.372, "")]
    wait_until(lambda: len(stored_rows(boat_db)) == 1, timeout=5, what="the boat's waypoint stored")
    assert [row[1:3] for row in stored_rows(boat_db)] == [(10.5, 59.9)]
    assert not (tmp_path / "fleet-boat.sqlite3").exists()


def test_a_livemap_goal_goes_to_the_robot_s_goal_pose_only(fleet_server, ros_peer):
    server = fleet_server()
    boat = server.robot["boat"]
    maps = get(boat + "/api/maps")
    name = quote(maps["default"], safe="")
    assert maps["maps"][0]["urls"]["goal"].startswith("/robots/boat/api/maps/")
    peer = ros_peer("goal_listener")
    topics = listen(peer, GOAL, "goal_pose")
    # Discovery matches both ends a moment apart: send goals until one is heard.
    wait_until(lambda: post(f"{boat}/api/maps/{name}/goal", {"x": 1.0, "y": 1.0}).ok and peer.received(topics["boat"]),
               timeout=15, interval=0.1, what="the boat's goal heard")
    time.sleep(SETTLE_S)
    peer.clear(topics["boat"])

    response = post(f"{boat}/api/maps/{name}/goal", {"x": 3.5, "y": 2.5, "yaw": 0.0})
    assert response.status_code == 200, response.text
    assert response.json()["topic"] == "/boat/goal_pose"
    goal = peer.wait_for(topics["boat"], timeout=5)["msg"]
    assert (goal["pose"]["position"]["x"], goal["pose"]["position"]["y"]) == (3.5, 2.5)
    time.sleep(SETTLE_S)
    assert len(peer.received(topics["boat"])) == 1
    assert peer.received(topics["drone"]) == []
    assert peer.received(topics["root"]) == []
