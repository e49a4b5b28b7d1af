"""Another process's parameters: listed with type, value, descriptor; set; every refusal."""

import pytest

from rover_web.ros_admin.service import RosAdmin
from tests.integration.ros_admin.conftest import PEER, PEER_URL, wait_for_parameters

pytestmark = pytest.mark.ros


def put(client, name, value):
    return client.put(f"{PEER_URL}/parameters/{name}", json={"value": value})


def test_parameters_are_listed_with_types_values_and_descriptors(client, admin_peer):
    params = wait_for_parameters(client)
    builtin = ("use_sim_time", "start_type_description_service")
    assert {n: (p["type"], p["value"]) for n, p in params.items() if n not in builtin} == {
        "flag": ("bool", True), "count": ("integer", 3), "gain": ("double", 0.5), "label": ("string", "hello"),
        "ids": ("integer_array", [1, 2, 3]), "weights": ("double_array", [0.5, 1.5]),
        "names": ("string_array", ["a", "b"]), "flags": ("bool_array", [True, False]),
        "serial": ("string", "SN-1"), "speed": ("double", 1.0), "level": ("integer", 4), "guarded": ("string", "ok"),
        "ntrip_password": ("string", "hunter2")}
    assert params["flag"]["description"] == "a switch"
    assert params["serial"]["read_only"] is True and params["flag"]["read_only"] is False
    assert params["speed"]["range"] == {"kind": "double", "from": 0.0, "to": 2.0, "step": 0.0}
    assert params["level"]["range"] == {"kind": "integer", "from": 0, "to": 10, "step": 2}


NEW_VALUES = [("flag", False), ("count", -7), ("gain", 2.25), ("label", "héllo wörld"), ("ids", [4, 5]),
              ("weights", [1.0, -2.5, 3.0]), ("names", ["x"]), ("flags", [False]), ("speed", 2.0), ("level", 8)]


def test_each_type_is_set_and_read_back(client, admin_peer):
    # One node for every type: each set is answered with its value, and the node reads each back.
    wait_for_parameters(client)
    for name, value in NEW_VALUES:
        response = put(client, name, value)
        assert response.status_code == 200, (name, response.get_json())
        assert response.get_json()["value"] == value
        assert wait_for_parameters(client)[name]["value"] == value, name


REFUSALS = [
    ("flag", 1, 400, "bad_type"),
    ("count", 1.5, 400, "bad_type"),
    ("count", "3", 400, "bad_type"),
    ("count", 2**63, 400, "out_of_range"),
    ("gain", "fast", 400, "bad_type"),
    ("ids", [1, "2"], 400, "bad_type"),
    ("label", None, 400, "bad_type"),
    ("speed", 2.5, 400, "out_of_range"),
    ("speed", -0.1, 400, "out_of_range"),
    ("level", 3, 400, "out_of_range"),
    ("level", 12, 400, "out_of_range"),
    ("serial", "SN-2", 409, "read_only"),
    ("guarded", "forbidden", 409, "refused_by_node"),
    ("missing", 1, 404, "unknown_parameter"),
]


def test_every_refusal_changes_nothing(client, admin_peer):
    # One node for every case: each is refused by name, and the node's parameters are as they were.
    before = wait_for_parameters(client)
    for name, value, status, code in REFUSALS:
        response = put(client, name, value)
        assert (response.status_code, response.get_json()["error"]) == (status, code), (name, response.get_json())
        if code == "refused_by_node":
            assert "guarded may not be forbidden" in response.get_json()["message"]
        assert wait_for_parameters(client) == before, name


def test_non_finite_numbers_never_reach_the_node(client, admin_peer):
    wait_for_parameters(client)
    response = client.put(f"{PEER_URL}/parameters/gain", data='{"value": NaN}', content_type="application/json")
    assert response.status_code == 400
    response = client.put(f"{PEER_URL}/parameters/gain", data='{"value": 1e400}', content_type="application/json")
    assert response.status_code == 400
    assert wait_for_parameters(client)["gain"]["value"] == 0.5


def test_a_node_that_does_not_answer_is_504(client, admin_peer):
    wait_for_parameters(client)
    admin_peer.proc.send_signal(19)  # SIGSTOP: in the graph, but silent
    try:
        response = client.get(PEER_URL + "/parameters")
        assert response.status_code == 504 and response.get_json()["error"] == "no_answer"
        response = put(client, "count", 5)
        assert response.status_code == 504
    finally:
        admin_peer.proc.send_signal(18)  # SIGCONT


def test_unknown_and_malformed_node_names(client):
    assert client.get("/api/nodes/nobody_here/parameters").status_code == 404
    assert client.get("/api/nodes/9bad/parameters").get_json()["error"] == "bad_node_name"
    assert client.put("/api/nodes/a b/parameters/x", json={"value": 1}).status_code == 400


def test_sets_and_refusals_go_to_the_operator_log(app, client, admin_peer):
    wait_for_parameters(client)
    assert put(client, "count", 9).status_code == 200
    assert put(client, "serial", "x").status_code == 409
    entries = client.get("/api/ros/log").get_json()["entries"]
    assert [(e["control"], e["label"], e["value"], e["result"]) for e in entries[:2]] == [
        ("set_parameter", f"{PEER} serial", "x", "refused"), ("set_parameter", f"{PEER} count", 9, "sent")]
    assert app.extensions["rover_web"].feature(RosAdmin).recent(1)[0]["reason"].startswith("read_only")


def test_nodes_are_listed_with_their_services(client, admin_peer):
    from tests.support.waiting import wait_until

    node = wait_until(lambda: next((n for n in client.get("/api/nodes").get_json()["nodes"]
                                    if n["name"] == PEER and n["services"]), None), 15, "the peer node")
    assert node["namespace"] == "/peer_ns" and node["node"] == "param_peer"
    services = {s["name"]: s["types"] for s in node["services"]}
    assert services["/peer_ns/set_enabled"] == ["std_srvs/srv/SetBool"]
    assert "/peer_ns/param_peer/set_parameters" in services
