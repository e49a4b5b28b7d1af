"""`python -m rover_web.sim --robots ...` in its own process, watched and driven by a real ROS peer."""

import time

from rover_web.sim.robots import SPACING_EAST_M
from tests.support.waiting import wait_until

# Infrastructure every rclpy node has; anything else the simulator makes must be under a robot's namespace.
ROS_OWN = {"/rosout", "/parameter_events"}
CAMERA = ("--camera-hz", "2", "--camera-size", "64", "48")  # the drone's camera, kept light on a shared machine


def drive(peer, topic: str, linear: float, seconds: float) -> None:
    """Command for `seconds`, faster than the simulator's 0.5 s command timeout."""
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        peer.publish(topic, {"linear": {"x": linear}})
        time.sleep(0.1)


def x_of(event) -> float:
    return event["msg"]["pose"]["pose"]["position"]["x"]


def test_boat_and_drone_run_in_their_namespaces_and_driving_the_boat_moves_only_the_boat(sim_process, ros_peer):
    sim = sim_process("--robots", "boat,drone", *CAMERA)
    peer = ros_peer()
    peer.subscribe("/boat/odom", "nav_msgs/msg/Odometry")
    peer.subscribe("/drone/status", "std_msgs/msg/String")
    peer.subscribe("/drone/location", "geometry_msgs/msg/Point")
    start = peer.wait_for("/boat/odom", timeout=20)
    assert peer.wait_for("/drone/status", timeout=20)["msg"]["data"] == "Standby"
    assert peer.wait_for("/drone/location")["msg"] == {"x": 0.0, "y": 0.0, "z": 0.0}

    namespaced = {
        "/boat/cmd_vel": "subscribers", "/boat/goal_pose": "subscribers", "/boat/light_buoy/new_code": "subscribers",
        "/boat/odom": "publishers", "/boat/fix": "publishers", "/boat/amcl_pose": "publishers",
        "/boat/diagnostics": "publishers", "/boat/light_sequence": "publishers",
        "/boat/tf": "publishers", "/boat/tf_static": "publishers",  # its frames, as Nav2's multi-robot remaps
        "/drone/control_phase": "subscribers", "/drone/flight_destination": "subscribers",
        "/drone/status": "publishers", "/drone/id": "publishers", "/drone/camera/image_raw": "publishers",
    }
    root = ["/tf", "/tf_static", "/cmd_vel", "/odom", "/fix", "/status", "/control_phase", "/camera/image_raw",
            "/light_sequence", "/diagnostics", "/drone/cmd_vel", "/drone/odom", "/boat/status",
            "/boat/camera/image_raw"]
    nodes = {"/boat/sim_rover", "/boat/light_buoy", "/drone/sim_drone", "/drone/sim_camera"}
    # Graph discovery lags data (node names later still): wait until every namespaced endpoint and
    # node is seen, then look for stray ones.
    graph = wait_until(lambda: (g := peer.graph(count_topics=[*namespaced, *root]))
                       and all(g[side][topic] >= 1 for topic, side in namespaced.items())
                       and nodes <= set(g["nodes"]) and g,
                       20, "every namespaced topic and node of the boat and the drone")
    assert {t: (graph["publishers"][t], graph["subscribers"][t]) for t in root} == {t: (0, 0) for t in root}
    def strays_in(g):
        outside = [t for t in g["topics"] if t not in ROS_OWN and not t.startswith(("/boat/", "/drone/"))]
        # What the simulators publish outside their namespaces. A topic only subscribed to is not
        # theirs (they subscribe only inside them, checked above): a rover_web server of an earlier
        # test on this domain subscribes to Nav2's action feedback and status at the root.
        published = peer.graph(count_topics=outside)["publishers"] if outside else {}
        return [t for t in outside if published.get(t, 0) > 0]

    # A process of an earlier test on this domain may still be in the graph until discovery sees it
    # leave (its topics linger a few seconds): a stray must stay to count.
    deadline = time.monotonic() + 10
    strays = strays_in(graph)
    while strays and time.monotonic() < deadline:
        time.sleep(0.5)
        strays = strays_in(peer.graph(count_topics=[]))
    assert strays == []

    assert abs(start["msg"]["twist"]["twist"]["linear"]["x"]) < 1e-9  # at rest until commanded
    peer.advertise("/boat/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_match("/boat/cmd_vel")
    drive(peer, "/boat/cmd_vel", 1.0, 1.0)
    moving = peer.wait_for("/boat/odom", lambda m: m["twist"]["twist"]["linear"]["x"] == 1.0)
    assert peer.wait_for("/boat/odom", lambda m: m["pose"]["pose"]["position"]["x"] > x_of(start) + 0.3)
    assert x_of(moving) > x_of(start)
    # The drone heard nothing: still on its pad, every report since the start the same.
    peer.clear("/drone/status")
    peer.wait_for("/drone/status")
    assert {e["msg"]["data"] for e in peer.received("/drone/status")} == {"Standby"}
    assert {tuple(e["msg"].values()) for e in peer.received("/drone/location")} == {(0.0, 0.0, 0.0)}

    assert sim.stop() == 0
    output = "".join(sim.output)
    assert "simulator stopped\n" in output
    assert "light buoy stopped (/boat):" in output  # which boat's buoy, when there are several
    assert "Traceback" not in output


def test_two_driving_robots_start_apart_and_each_obeys_only_its_own_cmd_vel(sim_process, ros_peer):
    sim_process("--robots", "boat,rover2", "--only", "rover", "--start", "0", "0", "0")
    peer = ros_peer()
    for name in ("boat", "rover2"):
        peer.subscribe(f"/{name}/odom", "nav_msgs/msg/Odometry")
        peer.subscribe(f"/{name}/fix", "sensor_msgs/msg/NavSatFix")
    boat, rover = peer.wait_for("/boat/odom", timeout=20), peer.wait_for("/rover2/odom", timeout=20)
    assert (x_of(boat), x_of(rover)) == (0.0, SPACING_EAST_M)
    boat_fix, rover_fix = peer.wait_for("/boat/fix")["msg"], peer.wait_for("/rover2/fix")["msg"]
    assert rover_fix["longitude"] > boat_fix["longitude"]  # east on the GPS map too
    assert rover_fix["latitude"] == boat_fix["latitude"]

    peer.advertise("/rover2/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_match("/rover2/cmd_vel")
    peer.clear("/boat/odom")
    drive(peer, "/rover2/cmd_vel", -1.0, 1.0)
    assert peer.wait_for("/rover2/odom", lambda m: m["pose"]["pose"]["position"]["x"] < SPACING_EAST_M - 0.3)
    peer.wait_for("/boat/odom")
    assert {(x_of(e), e["msg"]["twist"]["twist"]["linear"]["x"]) for e in peer.received("/boat/odom")} == {(0.0, 0.0)}
