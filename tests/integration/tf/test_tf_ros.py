"""TF from real rclpy peers in other processes: /tf_static (transient local, published before the server
starts) and /tf, looked up through GET /api/tf/lookup with hand-computed expectations; each warning the
TF page shows, provoked by a peer; and per robot namespace."""

import math
import time

import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

TF = "tf2_msgs/msg/TFMessage"
S45, C45, S15, C15 = math.sin(math.pi / 4), math.cos(math.pi / 4), math.sin(math.pi / 12), math.cos(math.pi / 12)
# The laser: 0.3 m ahead, 0.1 m right, 0.2 m up, turned 90° left (about z) and tilted 30° down (about
# its own y): q = qz(90°) ⊗ qy(30°) = (-s45·s15, c45·s15, s45·c15, c45·c15).
LASER_Q = (-S45 * S15, C45 * S15, S45 * C15, C45 * C15)


def transform(parent, child, t, q, stamp_s=0.0):
    sec = int(stamp_s)
    return {"header": {"stamp": {"sec": sec, "nanosec": int(round((stamp_s - sec) * 1e9))}, "frame_id": parent},
            "child_frame_id": child,
            "transform": {"translation": dict(zip("xyz", map(float, t), strict=True)),
                          "rotation": dict(zip("xyzw", map(float, q), strict=True))}}


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def lookup(server, target, source, time_s=None, prefix=""):
    params = {"target": target, "source": source}
    if time_s is not None:
        params["time"] = repr(time_s)
    return requests.get(f"{server.url}{prefix}/api/tf/lookup", params=params, timeout=5)


def tree(server, prefix=""):
    return requests.get(f"{server.url}{prefix}/api/tf", timeout=5).json()


def test_a_tilted_off_centre_laser_through_static_and_dynamic_transforms(live_server_factory, ros_peer):
    peer = ros_peer("tf_peer")
    peer.advertise("/tf_static", TF, qos="latched")
    # Published before the server exists: only a transient-local subscription can still get it.
    peer.publish("/tf_static", {"transforms": [transform("map", "odom", (10, 5, 0), (0, 0, 0, 1)),
                                               transform("base_link", "laser", (0.3, -0.1, 0.2), LASER_Q)]})
    server = live_server_factory()
    peer.advertise("/tf", TF, qos=100)
    peer.wait_match("/tf")
    t1 = float(int(time.time()) - 1)
    peer.publish("/tf", {"transforms": [transform("odom", "base_link", (1, 0, 0), yaw_q(0), t1)]})
    peer.publish("/tf", {"transforms": [transform("odom", "base_link", (3, 0, 0), yaw_q(math.pi / 2), t1 + 1)]})
    wait_until(lambda: (f := tree(server)["frames"]).get("base_link", {}).get("oldest_stamp") == t1
               and f["base_link"]["newest_stamp"] == t1 + 1 and "laser" in f and "odom" in f, 10,
               "both odometry transforms and the static ones")

    # At t1 the robot is at odom (1, 0), facing +x: the laser at map (10+1+0.3, 5-0.1, 0.2).
    got = lookup(server, "map", "laser", t1).json()
    assert got["translation"] == pytest.approx([11.3, 4.9, 0.2], abs=1e-9)
    assert got["rotation"] == pytest.approx(list(LASER_Q), abs=1e-9)
    assert got["stamp"] == pytest.approx(t1)
    # At t1+1 it faces +y: the laser's offset (0.3, -0.1) turned 90° is (0.1, 0.3), from (13, 5).
    assert lookup(server, "map", "laser", t1 + 1).json()["translation"] == pytest.approx([13.1, 5.3, 0.2], abs=1e-9)
    # Half way: translation halfway (12, 5), heading 45° (slerp between 0° and 90°).
    half = lookup(server, "map", "base_link", t1 + 0.5).json()
    assert half["translation"] == pytest.approx([12.0, 5.0, 0.0], abs=1e-6)
    assert half["yaw"] == pytest.approx(math.pi / 4, abs=1e-6)
    # No time: the latest common time, t1+1.
    latest = lookup(server, "map", "base_link").json()
    assert latest["stamp"] == pytest.approx(t1 + 1) and latest["yaw"] == pytest.approx(math.pi / 2)
    # The other way round, static only: base_link's origin in the laser frame is -R^T t, with
    # R^T = Ry(-30°) Rz(-90°): Rz(-90°)(0.3, -0.1, 0.2) = (-0.1, -0.3, 0.2); Ry(-30°) of that is
    # (c·-0.1 - s·0.2, -0.3, s·-0.1 + c·0.2) = (-0.1866, -0.3, 0.1232); negated.
    back = lookup(server, "laser", "base_link").json()
    c30, s30 = math.cos(math.pi / 6), math.sin(math.pi / 6)
    assert back["translation"] == pytest.approx([0.1 * c30 + 0.2 * s30, 0.3, 0.1 * s30 - 0.2 * c30], abs=1e-9)
    assert back["stamp"] == 0

    # tf2's refusals, with how far.
    future = lookup(server, "map", "laser", t1 + 3)
    assert future.status_code == 409 and future.json()["error"] == "extrapolation_future"
    assert future.json()["detail"]["by_s"] == pytest.approx(2.0, abs=1e-6)
    assert "2.000 s into the future" in future.json()["message"]
    past = lookup(server, "map", "laser", t1 - 0.25)
    assert past.status_code == 409 and past.json()["error"] == "extrapolation_past"
    assert past.json()["detail"]["by_s"] == pytest.approx(0.25, abs=1e-6)
    unknown = lookup(server, "map", "camera")
    assert unknown.status_code == 404 and unknown.json()["error"] == "unknown_frame"
    assert lookup(server, "map", "laser", "soon").status_code == 400

    # The tree: parents, kinds, rate, and who publishes.
    t = tree(server)
    assert t["available"] is True and t["roots"] == ["map"]
    assert t["frames"]["laser"]["parent"] == "base_link" and t["frames"]["laser"]["static"] is True
    assert t["frames"]["base_link"]["static"] is False and t["frames"]["base_link"]["rate_hz"] == pytest.approx(1.0)
    assert t["frames"]["map"]["children"] == ["odom"]
    wait_until(lambda: {"/tf_peer"} <= set((p := tree(server)["publishers"])["dynamic"]) & set(p["static"]), 10,
               "the peer named among the publishers")  # a node's name can come after its endpoints
    page = requests.get(server.url + "/tf", timeout=5).text
    assert "laser" in page and "base_link" in page


def kinds(server):
    return {w["kind"]: w for w in tree(server)["warnings"]}


def test_each_warning_of_the_tf_page_provoked_by_peers(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_TF_STALE_S=0.5)
    amcl, ekf = ros_peer("amcl_like"), ros_peer("ekf_like")
    for peer in (amcl, ekf):
        peer.advertise("/tf", TF, qos=100)
        peer.wait_match("/tf")
    now = time.time()
    # A frame with two parents: two nodes both claim odom, under different parents.
    amcl.publish("/tf", {"transforms": [transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), now)]})
    ekf.publish("/tf", {"transforms": [transform("world", "odom", (0, 0, 0), (0, 0, 0, 1), now + 0.01)]})
    two = wait_until(lambda: kinds(server).get("two_parents"), 10, "the two-parents warning")
    assert two["frame"] == "odom" and {p["parent"] for p in two["parents"]} == {"map", "world"}
    # A loop, a stamp in the future, an unnormalised quaternion, a stale frame, a second tree.
    amcl.publish("/tf", {"transforms": [
        transform("a", "b", (0, 0, 0), (0, 0, 0, 1), now), transform("b", "c", (0, 0, 0), (0, 0, 0, 1), now),
        transform("c", "a", (0, 0, 0), (0, 0, 0, 1), now),
        transform("odom", "gps", (0, 0, 0), (0, 0, 0, 1), time.time() + 30),
        transform("odom", "imu", (0, 0, 0), (0, 0, 0.5, 0.5), now),
        transform("odom", "wheel", (0, 0, 0), (0, 0, 0, 1), time.time()),
        transform("earth", "utm", (0, 0, 0), (0, 0, 0, 1), time.time() + 0.02)]})
    got = wait_until(lambda: (k := kinds(server)) and {"loop", "future", "unnormalised", "stale", "several_trees"}
                     <= set(k) and k, 10, "every warning")
    assert got["loop"]["frames"] == ["a", "c", "b"]
    assert got["future"]["frame"] == "gps" and got["future"]["ahead_s"] == pytest.approx(30, abs=2)
    assert got["unnormalised"]["frame"] == "imu" and got["unnormalised"]["norm"] == pytest.approx(math.sqrt(0.5))
    stale = wait_until(lambda: (f := {w["frame"] for w in tree(server)["warnings"] if w["kind"] == "stale"})
                       and "wheel" in f and f, 5, "wheel stale (0.5 s without a transform)")
    assert "gps" not in stale  # stamped ahead: in the future, not stale
    # earth's tree, and odom's root (map or world: whichever of the two publishers was heard last)
    roots = got["several_trees"]["roots"]
    assert "earth" in roots and len({"map", "world"} & set(roots)) == 1
    refused = lookup(server, "odom", "imu")
    assert refused.status_code == 404  # tf2 ignores a denormalised quaternion: imu has no transform
    page = requests.get(server.url + "/tf", timeout=5).text
    for text in ("more than one parent", "has a loop", "in the future", "norm 0.707107", "unconnected trees"):
        assert text in page


def test_each_robot_reads_tf_under_its_namespace(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_ROBOTS=[{"name": "boat"}, {"name": "rover"}])
    peer = ros_peer("ns_peer")
    peer.advertise("/boat/tf", TF, qos=100)
    peer.wait_match("/boat/tf")
    peer.publish("/boat/tf", {"transforms": [transform("odom", "base_link", (2, 0, 0), (0, 0, 0, 1), time.time())]})
    wait_until(lambda: "base_link" in tree(server, "/robots/boat")["frames"], 10, "the boat's frame")
    assert tree(server, "/robots/boat")["topics"] == {"dynamic": "/boat/tf", "static": "/boat/tf_static"}
    assert tree(server, "/robots/rover")["frames"] == {}
    assert lookup(server, "odom", "base_link", prefix="/robots/boat").json()["translation"] == [2.0, 0.0, 0.0]
    assert lookup(server, "odom", "base_link", prefix="/robots/rover").status_code == 404
