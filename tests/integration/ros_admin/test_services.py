"""Services of another process: listed, called, validated against their type, timed out."""

import queue

import pytest

from rover_web.ros_admin.service import RosAdmin
from tests.integration.ros_admin.conftest import wait_for_service
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

SET_BOOL = "std_srvs/srv/SetBool"


def call(client, service, type_name, request=None, **extra):
    body = {"service": service, "type": type_name, **extra}
    if request is not None:
        body["request"] = request
    return client.post("/api/services/call", json=body)


def test_services_are_listed_with_their_types(client, admin_peer):
    wait_for_service(client, "/peer_ns/set_enabled")
    services = {s["name"]: s["types"] for s in client.get("/api/services").get_json()["services"]}
    assert services["/peer_ns/set_enabled"] == [SET_BOOL]
    assert services["/peer_ns/trigger"] == ["std_srvs/srv/Trigger"]
    assert services["/peer_ns/reset"] == ["std_srvs/srv/Empty"]


def test_set_bool_trigger_and_empty_are_called(client, admin_peer):
    wait_for_service(client, "/peer_ns/set_enabled")
    response = call(client, "/peer_ns/set_enabled", SET_BOOL, {"data": True})
    assert response.status_code == 200, response.get_json()
    assert response.get_json()["response"] == {"success": True, "message": "enabled=True"}
    assert admin_peer.wait("called")["request"] == {"data": True}
    response = call(client, "/peer_ns/trigger", "std_srvs/srv/Trigger")
    assert response.get_json()["response"] == {"success": True, "message": "triggered"}
    assert call(client, "/peer_ns/reset", "std_srvs/srv/Empty", {}).get_json()["response"] == {}


@pytest.mark.parametrize("request_body,code,field", [
    ({"data": 1}, "bad_type", "request.data"),
    ({"data": True, "extra": 1}, "unknown_field", "request.extra"),
    ({"dta": True}, "unknown_field", "request.dta"),
    ([True], "bad_type", "request"),
])
def test_mistyped_requests_are_400_naming_the_field(client, admin_peer, request_body, code, field):
    wait_for_service(client, "/peer_ns/set_enabled")
    response = call(client, "/peer_ns/set_enabled", SET_BOOL, request_body)
    assert response.status_code == 400 and response.get_json()["error"] == code
    assert response.get_json()["message"].startswith(field)
    with pytest.raises(queue.Empty):  # nothing reached the peer
        admin_peer.wait("called", timeout=0.5)


@pytest.mark.parametrize("type_name,status,code", [
    ("nonexistent_pkg/srv/Thing", 422, "unknown_type"),
    ("json/srv/Thing", 422, "unknown_type"),  # a Python module, not a ROS interface package: never imported
    ("std_srvs/srv/Nope", 422, "unknown_type"),
    ("std_srvs/Trigger", 400, "bad_type_name"),
    ("std_srvs/srv/Trigger\n", 422, "unknown_type"),
])
def test_types_that_are_not_installed_interfaces(client, type_name, status, code):
    response = call(client, "/x", type_name, {})
    assert (response.status_code, response.get_json()["error"]) == (status, code)


def test_wrong_type_for_the_service_and_unknown_service(client, admin_peer):
    wait_for_service(client, "/peer_ns/set_enabled")
    response = call(client, "/peer_ns/set_enabled", "std_srvs/srv/Trigger")
    assert (response.status_code, response.get_json()["error"]) == (400, "type_mismatch")
    assert call(client, "/nobody/home", SET_BOOL, {"data": True}).status_code == 404
    assert call(client, "bad name", SET_BOOL).status_code == 400
    assert call(client, "/peer_ns/set_enabled", SET_BOOL, timeout_s=0).status_code == 400


def test_a_service_that_never_answers_is_504_after_the_timeout(client, admin_peer):
    wait_for_service(client, "/peer_ns/silent")
    response = call(client, "/peer_ns/silent", "std_srvs/srv/Trigger", timeout_s=0.5)
    assert (response.status_code, response.get_json()["error"]) == (504, "no_answer")
    assert admin_peer.wait("called")["service"] == "silent"  # it was called, and said nothing


def test_calls_are_refused_while_the_estop_is_engaged(client, admin_peer):
    wait_for_service(client, "/peer_ns/set_enabled")
    client.post("/api/estop", json={"engaged": True})
    response = call(client, "/peer_ns/set_enabled", SET_BOOL, {"data": True})
    assert (response.status_code, response.get_json()["error"]) == (409, "estop_engaged")
    entries = client.get("/api/ros/log").get_json()["entries"]
    assert (entries[0]["control"], entries[0]["result"], entries[0]["reason"]) == (
        "call_service", "refused", "estop_engaged")


def test_calls_go_to_the_operator_log_with_arguments_and_outcome(client, admin_peer):
    wait_for_service(client, "/peer_ns/set_enabled")
    call(client, "/peer_ns/set_enabled", SET_BOOL, {"data": True})
    call(client, "/peer_ns/set_enabled", SET_BOOL, {"data": "yes"})
    entries = client.get("/api/ros/log").get_json()["entries"]
    assert [(e["label"], e["value"], e["result"]) for e in entries[:2]] == [
        ("/peer_ns/set_enabled", {"type": SET_BOOL, "request": {"data": "yes"}}, "invalid"),
        ("/peer_ns/set_enabled", {"type": SET_BOOL, "request": {"data": True}}, "sent")]
    assert "enabled=True" in entries[1]["reason"]


def test_type_descriptions_for_generated_forms(client):
    body = client.get("/api/types/std_srvs/srv/SetBool").get_json()
    assert body["request"] == [{"name": "data", "type": "boolean", "kind": "bool"}]
    body = client.get("/api/types/test_msgs/action/Fibonacci").get_json()
    assert body["goal"] == [{"name": "order", "type": "int32", "kind": "int", "min": -2**31, "max": 2**31 - 1}]
    assert client.get("/api/types/json/srv/Thing").status_code == 422
    assert client.get("/api/types/std_srvs/srv/Nope").status_code == 404
    assert client.get("/api/types/std_srvs/foo/Trigger").status_code == 404


def test_during_the_estop_a_bad_request_is_still_400(client):
    client.post("/api/estop", json={"engaged": True})
    assert call(client, "/x", SET_BOOL, {"data": 1}).status_code == 400
    response = client.post("/api/actions/goal", json={"action": "/x", "type": "test_msgs/action/Fibonacci",
                                                      "goal": {"order": "many"}})
    assert (response.status_code, response.get_json()["error"]) == (400, "bad_type")
    response = client.post("/api/actions/goal", json={"action": "/x", "type": "test_msgs/action/Fibonacci"})
    assert (response.status_code, response.get_json()["error"]) == (409, "estop_engaged")


def test_the_main_node_gets_no_clients_from_these_calls(app, client, admin_peer):
    """Service clients live on the admin node: the main executor's wait set (teleop, events) is untouched."""
    node = app.extensions["rover_web"].runtime.node
    def counts(n):
        return len(list(n.clients)), len(list(n.waitables)), len(list(n.subscriptions))

    before = counts(node)
    wait_for_service(client, "/peer_ns/trigger")
    assert call(client, "/peer_ns/trigger", "std_srvs/srv/Trigger").status_code == 200
    # The node's name can be discovered a moment after its services: wait for it as for them.
    wait_until(lambda: client.get("/api/nodes/peer_ns/param_peer/parameters").status_code == 200, 15,
               "the peer's parameters listed")
    assert counts(node) == before
    admin_node = app.extensions["rover_web"].feature(RosAdmin).node._node
    assert counts(admin_node)[0] >= 4  # the Trigger client and the parameter clients are there instead
