"""The simulator behaves like a robot, seen from another process: its battery drains as it drives and
the GUI and the log read the same battery, it drives a mission sent with the REST API, and it stops at
the floorplan's walls."""

import math
import time

import pytest
import requests

from rover_web.sim.geodesy import enu_to_geodetic, geodetic_to_enu
from rover_web.sim.rover import BENDERSON_LAT, BENDERSON_LON, default_start
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros


def drive(peer, linear: float, seconds: float, topic: str = "/cmd_vel") -> None:
    """Command for `seconds`, faster than the simulator's 0.5 s command timeout."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        peer.publish(topic, {"linear": {"x": linear}})
        time.sleep(0.1)


def log_lines(server, contains: str) -> list[dict]:
    return requests.get(server.url + "/api/rosout", params={"contains": contains}, timeout=5).json()["lines"]


def test_the_gui_shows_the_battery_the_log_talks_about(live_server, sim_process):
    sim_process("--only", "rover", "--battery", "9")
    robot = wait_until(lambda: (r := requests.get(live_server.url + "/api/robots", timeout=5).json()["robots"][0])
                       and r["battery"] and r, 20, "the simulated battery on /api/robots")
    battery = robot["battery"]
    assert battery["percent"] == pytest.approx(9.0, abs=0.1)  # the Robot card's "9 %"
    assert 19.5 < battery["voltage"] < 22.5  # six Li-ion cells nearly empty, at rest
    assert battery["status"] == "discharging"
    line = wait_until(lambda: log_lines(live_server, "battery critically low"), 20, "the battery's log line")[0]
    assert line["level"] == 40  # ERROR
    assert line["msg"].startswith("battery critically low: 9 % (")  # the same number the card shows


def test_the_battery_drains_faster_while_driving(sim_process, ros_peer):
    sim_process("--only", "rover")
    peer = ros_peer()
    peer.subscribe("/battery_state", "sensor_msgs/msg/BatteryState", qos="sensor_data")
    first = peer.wait_for("/battery_state", timeout=20)["msg"]
    at_rest = peer.wait_for("/battery_state", lambda m: m["header"] != first["header"])["msg"]
    assert at_rest["current"] == pytest.approx(-1.5)  # negative: discharging
    rest_drop = first["percentage"] - at_rest["percentage"]
    assert 0 < rest_drop < 1e-4
    assert at_rest["percentage"] == pytest.approx(0.8, abs=0.001)
    assert at_rest["cell_voltage"] == [pytest.approx(at_rest["voltage"] / 6)] * 6

    peer.advertise("/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_match("/cmd_vel")
    peer.clear("/battery_state")
    drive(peer, 2.0, 3.5)
    loaded = [e["msg"] for e in peer.received("/battery_state") if e["msg"]["current"] < -20]
    assert len(loaded) >= 2, "no battery report while driving at 2 m/s"
    drive_drop = loaded[0]["percentage"] - loaded[1]["percentage"]
    assert drive_drop > 10 * rest_drop  # 25.5 A against 1.5 A
    assert loaded[-1]["voltage"] < at_rest["voltage"] - 1.0  # the pack sags under load


def fix_at(x: float, y: float):
    """A predicate: the NavSatFix is within 10 cm of map point (x, y)."""
    def near(msg) -> bool:
        east, north = geodetic_to_enu(msg["latitude"], msg["longitude"], BENDERSON_LAT, BENDERSON_LON)
        return math.hypot(east - x, north - y) < 0.1
    return near


def test_a_mission_sent_with_the_rest_api_is_driven_waypoint_after_waypoint(live_server, sim_process, ros_peer):
    x0, y0, _ = default_start()  # the basement's Dock, in a corridor running east
    sim_process("--only", "rover", "--goal-speed", "2.0")
    peer = ros_peer()
    peer.subscribe("/fix", "sensor_msgs/msg/NavSatFix", qos="sensor_data", max_items=2000)
    peer.subscribe("/plan", "nav_msgs/msg/Path")
    peer.wait_for("/fix", fix_at(x0, y0), timeout=20)
    stops = [(x0 + 3.0, y0), (x0 + 6.0, y0 - 0.5), (x0 + 3.5, y0 + 0.5)]
    for x, y in stops:
        lat, lng = enu_to_geodetic(x, y, BENDERSON_LAT, BENDERSON_LON)
        assert requests.post(live_server.url + "/api/waypoints", json={"lng": lng, "lat": lat}, timeout=5).ok

    # /mission is volatile, as a command should be: sent before discovery matched the simulator, it is lost.
    wait_until(lambda: (g := peer.graph(count_topics=["/mission"])) and g["subscribers"]["/mission"]
               and g["publishers"]["/mission"], 20, "the app's /mission publisher and the simulator's subscriber")

    def taken() -> bool:
        assert requests.post(live_server.url + "/api/waypoints/send", json={}, timeout=5).json()["sent"] == 3
        try:
            return bool(wait_until(lambda: log_lines(live_server, "mission of 3 waypoints received"), 5))
        except AssertionError:
            return False
    wait_until(taken, 30, "the simulator taking the mission", interval=0)

    plan = peer.wait_for("/plan", lambda m: len(m["poses"]) > 10)["msg"]["poses"]
    end = plan[-1]["pose"]["position"]
    assert (end["x"], end["y"]) == pytest.approx(stops[-1])  # the whole route, to the last waypoint
    for x, y in stops:  # in order: each wait starts from the messages seen so far
        peer.wait_for("/fix", fix_at(x, y), timeout=30)
    reached = wait_until(lambda: log_lines(live_server, "mission complete"), 10, "the mission's end in the log")
    assert reached[0]["msg"] == "mission complete: 3 waypoints"
    assert [line["msg"] for line in reversed(log_lines(live_server, "reached"))] == [
        f"mission: waypoint {i} of 3 reached" for i in (1, 2, 3)]
    fixes = [e["msg"] for e in peer.received("/fix")]
    order = [next(i for i, m in enumerate(fixes) if fix_at(x, y)(m)) for x, y in stops]
    assert order == sorted(order)


def test_the_rover_stops_at_a_wall_and_gives_up_a_goal_behind_it(sim_process, ros_peer):
    x0, y0, _ = default_start()  # a room's wall runs 1.5 m north of the Dock
    sim_process("--only", "rover", "--start", str(x0), str(y0), str(math.pi / 2))
    peer = ros_peer()
    peer.subscribe("/odom", "nav_msgs/msg/Odometry")
    peer.subscribe("/rosout", "rcl_interfaces/msg/Log", qos=100)
    peer.advertise("/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_for("/odom", timeout=20)
    peer.wait_match("/cmd_vel")
    drive(peer, 1.0, 3.0)  # 3 m north without the wall
    peer.clear("/odom")
    stopped = peer.wait_for("/odom")["msg"]["pose"]["pose"]["position"]
    assert 11.6 < stopped["y"] < 11.8 and stopped["x"] == pytest.approx(x0)  # a robot's radius short of y = 12

    peer.advertise("/goal_pose", "geometry_msgs/msg/PoseStamped")
    peer.wait_match("/goal_pose")
    peer.publish("/goal_pose", {"header": {"frame_id": "map"},
                                "pose": {"position": {"x": x0, "y": y0 + 3.0}, "orientation": {"w": 1.0}}})
    aborted = peer.wait_for("/rosout", lambda m: m["msg"].startswith("goal aborted: blocked by a wall"), timeout=20)
    assert aborted["msg"]["level"] == 30  # WARN: the navigator gave up, nothing is broken
    peer.clear("/odom")
    assert peer.wait_for("/odom")["msg"]["pose"]["pose"]["position"]["y"] < 11.8


def test_a_boat_is_on_the_water_where_the_floorplans_walls_are_not(sim_process, ros_peer):
    x0, y0, _ = default_start()
    sim_process("--robots", "boat", "--only", "rover", "--start", str(x0), str(y0), str(math.pi / 2))
    peer = ros_peer()
    peer.subscribe("/boat/odom", "nav_msgs/msg/Odometry")
    peer.advertise("/boat/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_for("/boat/odom", timeout=20)
    peer.wait_match("/boat/cmd_vel")
    drive(peer, 1.0, 3.0, topic="/boat/cmd_vel")
    assert peer.wait_for("/boat/odom", lambda m: m["pose"]["pose"]["position"]["y"] > 12.5)  # past y = 12
