"""POST /api/maps/<name>/initial_pose: a PoseWithCovarianceStamped heard by a real rclpy node.

The subscriber runs in another process (tests/support/rospeer.py); every refused body, and a pose
sent while the e-stop is engaged, must leave the topic silent.
"""

import math
import time
from urllib.parse import quote

import pytest
import requests

pytestmark = pytest.mark.ros

B = quote("Science Hall Basement")
POSE = "geometry_msgs/msg/PoseWithCovarianceStamped"
RVIZ = [0.0] * 36
RVIZ[0] = RVIZ[7] = 0.25
RVIZ[35] = (math.pi / 12) ** 2


def post(server, body, name=B):
    return requests.post(f"{server.url}/api/maps/{name}/initial_pose", json=body, timeout=5)


def yaw_of(q):
    return math.atan2(2 * (q.get("w", 0) * q.get("z", 0) + q.get("x", 0) * q.get("y", 0)),
                      1 - 2 * (q.get("y", 0) ** 2 + q.get("z", 0) ** 2))


@pytest.fixture
def listener(live_server, ros_peer):
    peer = ros_peer("initialpose_listener")
    peer.subscribe("/initialpose", POSE)
    peer.wait_match("/initialpose")
    return peer


def test_a_pose_with_the_default_and_a_given_covariance_reaches_a_subscriber(live_server, listener):
    response = post(live_server, {"x": 12.5, "y": 4.25, "yaw": 1.0})
    assert response.status_code == 200, response.text
    body = response.json()
    assert body["topic"] == "/initialpose" and body["status"] == "sent"
    assert (body["initial_pose"]["x"], body["initial_pose"]["y"], body["initial_pose"]["frame_id"]) == (12.5, 4.25,
                                                                                                        "map")
    msg = listener.wait_for("/initialpose")["msg"]
    assert msg["header"]["frame_id"] == "map"
    assert msg["header"]["stamp"]["sec"] > 0  # stamped now, so AMCL does not take it for an old message
    pose = msg["pose"]["pose"]
    assert (pose["position"]["x"], pose["position"]["y"]) == (12.5, 4.25)
    assert yaw_of(pose["orientation"]) == pytest.approx(1.0, abs=1e-9)
    assert msg["pose"]["covariance"] == pytest.approx(RVIZ)

    mine = [0.0] * 36
    mine[0], mine[1], mine[6], mine[7], mine[35] = 0.04, 0.01, 0.01, 0.09, 0.5
    assert post(live_server, {"x": 3.0, "y": 2.0, "yaw": -4.0, "covariance": mine}).status_code == 200
    msg = listener.wait_for("/initialpose", lambda m: m["pose"]["pose"]["position"]["x"] == 3.0)["msg"]
    assert msg["pose"]["covariance"] == pytest.approx(mine)
    assert yaw_of(msg["pose"]["pose"]["orientation"]) == pytest.approx(-4.0 + 2 * math.pi)  # wrapped


def asymmetric():
    cov = [0.0] * 36
    cov[1] = 0.5
    return cov


BAD_BODIES = [
    ({"y": 1.0}, "missing_field"),
    ({"x": "1", "y": 1.0}, "bad_type"),
    ({"x": True, "y": 1.0}, "bad_type"),
    ({"x": 1.0, "y": 1.0, "theta": 0}, "unknown_field"),
    ({"x": 1.0, "y": 1.0, "covariance": [0.1] * 35}, "bad_type"),
    ({"x": 1.0, "y": 1.0, "covariance": "small"}, "bad_type"),
    ({"x": 1.0, "y": 1.0, "covariance": [-1.0] + [0.0] * 35}, "out_of_range"),
    ({"x": 1.0, "y": 1.0, "covariance": [1e9] + [0.0] * 35}, "out_of_range"),
    ({"x": 1.0, "y": 1.0, "covariance": [None] * 36}, "bad_type"),
    ({"x": 1.0, "y": 1.0, "covariance": asymmetric()}, "bad_value"),
    ({"x": 500.0, "y": 1.0}, "outside_map"),
]
BAD_RAW = [(b'{"x": NaN, "y": 1}', "non_finite"), (b'{"x": 1e999, "y": 1}', "non_finite"),
           (b'{"x": 1, "y": 1, "covariance": [Infinity' + b', 0' * 35 + b']}', "non_finite"),
           (b"[1, 2]", None), (b"{", "bad_json")]


def test_bad_input_is_400_json_and_publishes_nothing(live_server, listener):
    # One server and one listener for every case: each is refused by name, and none publishes.
    for body, code in BAD_BODIES:
        response = post(live_server, body)
        assert response.status_code == 400, (body, response.text)
        assert response.json()["error"] == code, body
    for raw, code in BAD_RAW:
        response = requests.post(f"{live_server.url}/api/maps/{B}/initial_pose", data=raw, timeout=5,
                                 headers={"Content-Type": "application/json"})
        assert response.status_code == 400 and response.headers["Content-Type"].startswith("application/json"), raw
        if code:
            assert response.json()["error"] == code, raw
    time.sleep(0.3)
    assert listener.received("/initialpose") == []


def test_an_unknown_map_is_404(live_server, listener):
    response = post(live_server, {"x": 1.0, "y": 1.0}, name="Attic")
    assert response.status_code == 404 and response.json()["error"] == "unknown_map"


def test_refused_while_the_estop_is_engaged_and_sent_again_after_release(live_server, listener):
    assert requests.post(live_server.url + "/api/estop", json={"engaged": True}, timeout=5).status_code == 200
    refused = post(live_server, {"x": 5.0, "y": 5.0})
    assert refused.status_code == 409 and refused.json()["error"] == "estop_engaged"
    time.sleep(0.5)
    assert listener.received("/initialpose") == []
    assert requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5).status_code == 200
    assert post(live_server, {"x": 5.0, "y": 5.0}).status_code == 200
    listener.wait_for("/initialpose", lambda m: m["pose"]["pose"]["position"]["x"] == 5.0)


def test_the_topic_comes_from_the_setting(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_INITIAL_POSE_TOPIC="/robot1/initialpose")
    peer = ros_peer("initialpose_listener_ns")
    peer.subscribe("/robot1/initialpose", POSE)
    peer.wait_match("/robot1/initialpose")
    response = post(server, {"x": 2.0, "y": 10.5})
    assert response.status_code == 200 and response.json()["topic"] == "/robot1/initialpose"
    peer.wait_for("/robot1/initialpose")


def test_the_simulator_takes_the_initial_pose_as_amcl_would(live_server, sim_process):
    sim_process()
    at = lambda: requests.get(f"{live_server.url}/api/maps/{B}", timeout=5).json()["map_parameters"]["current_pose"]  # noqa: E731
    deadline = time.monotonic() + 20
    while not at():
        assert time.monotonic() < deadline, "the simulator's pose never arrived"
        time.sleep(0.2)
    assert post(live_server, {"x": 30.0, "y": 19.0, "yaw": math.pi}).status_code == 200
    deadline = time.monotonic() + 10
    while not (pose := at()) or abs(pose["x"] - 30.0) > 1e-6:
        assert time.monotonic() < deadline, f"the simulator did not move to the initial pose: {pose}"
        time.sleep(0.2)
    assert pose["y"] == pytest.approx(19.0) and abs(pose["yaw"]) == pytest.approx(math.pi, abs=1e-6)
