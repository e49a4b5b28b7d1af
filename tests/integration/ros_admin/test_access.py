"""Who may write to the ROS graph from /ros, and what nobody may (issue 27): real peers in other processes.

Writes are admin work; the deny list holds back even an admin; safety nodes keep their parameters
while the e-stop is engaged; ROVER_WEB_ROS_ADMIN turns it all read-only or off; navigation goals
go through the routes that check keep-out areas and the geofence.
"""

import queue

import pytest
import requests

from tests.integration.ros_admin.conftest import PEER, PEER_URL, wait_for_parameters, wait_for_service
from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

SET_BOOL = "std_srvs/srv/SetBool"
FIB = "test_msgs/action/Fibonacci"


def as_user(server, role):
    return {"Authorization": f"Bearer {server.tokens[role]}"}


def live_parameters(server, role="admin"):
    def listed():
        response = requests.get(server.url + PEER_URL + "/parameters", headers=as_user(server, role), timeout=10)
        return response.status_code == 200 and {p["name"]: p for p in response.json()["parameters"]}
    return wait_until(listed, 15, "the peer's parameters")


def action_listed(url, action, headers=None):
    def listed():
        nodes = requests.get(url + "/api/nodes", headers=headers or {}, timeout=5).json()["nodes"]
        return any(a["name"] == action for n in nodes for a in n["action_servers"])
    wait_until(listed, 15, f"action server {action}")


def nothing_more(peer, event, timeout=1.0):
    with pytest.raises(queue.Empty):
        peer.wait(event, timeout=timeout)


def test_an_operator_may_not_write_to_the_graph_and_an_admin_may(signed_server, admin_peer, action_peer):
    fib = action_peer()
    url = signed_server.url
    operator, admin = as_user(signed_server, "operator"), as_user(signed_server, "admin")
    live_parameters(signed_server)
    action_listed(url, "/fibonacci", admin)

    response = requests.put(f"{url}{PEER_URL}/parameters/count", json={"value": 7}, headers=operator, timeout=10)
    assert (response.status_code, response.json()["error"]) == (403, "forbidden"), response.text
    response = requests.post(url + "/api/services/call", headers=operator, timeout=10,
                             json={"service": "/peer_ns/set_enabled", "type": SET_BOOL, "request": {"data": True}})
    assert (response.status_code, response.json()["error"]) == (403, "forbidden"), response.text
    response = requests.post(url + "/api/actions/goal", headers=operator, timeout=10,
                             json={"action": "/fibonacci", "type": FIB, "goal": {"order": 3}})
    assert (response.status_code, response.json()["error"]) == (403, "forbidden"), response.text
    assert live_parameters(signed_server)["count"]["value"] == 3
    nothing_more(admin_peer, "called")
    nothing_more(fib, "accepted")

    response = requests.put(f"{url}{PEER_URL}/parameters/count", json={"value": 7}, headers=admin, timeout=10)
    assert response.status_code == 200, response.text
    wait_for = requests.post(url + "/api/services/call", headers=admin, timeout=10,
                             json={"service": "/peer_ns/set_enabled", "type": SET_BOOL, "request": {"data": True}})
    assert wait_for.status_code == 200, wait_for.text
    assert admin_peer.wait("called")["request"] == {"data": True}
    response = requests.post(url + "/api/actions/goal", headers=admin, timeout=15,
                             json={"action": "/fibonacci", "type": FIB, "goal": {"order": 3}})
    assert response.status_code == 200, response.text
    fib.wait("accepted")
    assert live_parameters(signed_server)["count"]["value"] == 7


def test_the_default_deny_list_holds_back_an_admin_too(client, admin_peer):
    """Sign-in off on loopback: every caller is an admin, and the deny list still refuses."""
    before = wait_for_parameters(client)
    response = client.put(f"{PEER_URL}/parameters/use_sim_time", json={"value": True})
    assert (response.status_code, response.get_json()["error"]) == (403, "denied")
    assert "param:use_sim_time" in response.get_json()["message"]
    assert "ROVER_WEB_ROS_ADMIN_DENY" in response.get_json()["message"]
    # The parameter services themselves: setting through them would skip every check above.
    wait_for_service(client, f"{PEER}/set_parameters")
    response = client.post("/api/services/call", json={
        "service": f"{PEER}/set_parameters", "type": "rcl_interfaces/srv/SetParameters",
        "request": {"parameters": [{"name": "use_sim_time", "value": {"type": 1, "bool_value": True}}]}})
    assert (response.status_code, response.get_json()["error"]) == (403, "denied")
    assert "service:*/set_parameters*" in response.get_json()["message"]
    assert wait_for_parameters(client) == before
    entries = client.get("/api/ros/log").get_json()["entries"]
    assert [(e["control"], e["result"], e["reason"].split(":")[0]) for e in entries[:2]] == [
        ("call_service", "refused", "denied"), ("set_parameter", "refused", "denied")]
    # The page shows the parameter services' rows as refused.
    listed = client.get(PEER_URL + "/parameters").get_json()["parameters"]
    assert next(p for p in listed if p["name"] == "use_sim_time")["refused"]
    assert next(p for p in listed if p["name"] == "count")["refused"] is None


def test_deny_by_node_reaches_the_services_that_node_serves(app_factory, admin_peer):
    client = app_factory(ROVER_WEB_ROS_ADMIN_DENY=["node:/peer_ns/param_peer"]).test_client()
    wait_for_parameters(client)
    response = client.put(f"{PEER_URL}/parameters/count", json={"value": 5})
    assert (response.status_code, response.get_json()["error"]) == (403, "denied")
    wait_for_service(client, "/peer_ns/set_enabled")
    response = client.post("/api/services/call", json={"service": "/peer_ns/set_enabled", "type": SET_BOOL,
                                                       "request": {"data": True}})
    assert (response.status_code, response.get_json()["error"]) == (403, "denied"), response.get_json()
    nothing_more(admin_peer, "called")
    # Setting the list replaces the defaults: use_sim_time is not held back any more (only this node is).
    assert wait_for_parameters(client)["count"]["value"] == 3


def test_an_allow_list_lets_through_only_what_it_names(app_factory, admin_peer):
    client = app_factory(ROVER_WEB_ROS_ADMIN_ALLOW=["service:/peer_ns/set_enabled", "param:gain"]).test_client()
    wait_for_parameters(client)
    wait_for_service(client, "/peer_ns/trigger")
    assert client.put(f"{PEER_URL}/parameters/gain", json={"value": 1.5}).status_code == 200
    response = client.put(f"{PEER_URL}/parameters/count", json={"value": 5})
    assert (response.status_code, response.get_json()["error"]) == (403, "not_allowed")
    assert "ROVER_WEB_ROS_ADMIN_ALLOW" in response.get_json()["message"]
    response = client.post("/api/services/call", json={"service": "/peer_ns/trigger", "type": "std_srvs/srv/Trigger"})
    assert (response.status_code, response.get_json()["error"]) == (403, "not_allowed")
    response = client.post("/api/services/call", json={"service": "/peer_ns/set_enabled", "type": SET_BOOL,
                                                       "request": {"data": True}})
    assert response.status_code == 200, response.get_json()
    assert admin_peer.wait("called")["service"] == "set_enabled"
    params = wait_for_parameters(client)
    assert (params["gain"]["value"], params["count"]["value"]) == (1.5, 3)


def test_a_bad_rule_stops_the_app_at_start(app_factory):
    from rover_web.config import ConfigError

    with pytest.raises(ConfigError, match="ROVER_WEB_ROS_ADMIN_DENY.*topic:/x"):
        app_factory(ROVER_WEB_ROS_ADMIN_DENY=["topic:/x"])


def docs_example_deny() -> list[str]:
    """The ROVER_WEB_ROS_ADMIN_DENY of docs/ros_admin.md's example."""
    from rover_web.config import ROOT

    text = (ROOT / "docs" / "ros_admin.md").read_text()
    line = next(line for line in text.splitlines() if line.startswith("ROVER_WEB_ROS_ADMIN_DENY='"))
    return line.split("'")[1].split(",")


def dropped_warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records
            if r.levelname == "WARNING" and "ROVER_WEB_ROS_ADMIN_DENY replaces" in r.getMessage()]


def test_a_deny_list_that_leaves_out_defaults_is_warned_of_at_start(app_factory, caplog):
    caplog.set_level("WARNING", logger="rover_web")
    app_factory(ROVER_WEB_ROS_ADMIN_DENY=["param:use_sim_time", "service:*/set_parameters*", "service:*/change_state",
                                          "service:*/_action/*", "service:*/_container/*", "node:/px4*"])
    [warning] = dropped_warnings(caplog)
    assert "2 of its entries" in warning
    assert "service:*/load_parameters" in warning and "service:*/manage_nodes" in warning
    assert "use_sim_time" not in warning and "change_state" not in warning
    assert "docs/ros_admin.md" in warning


@pytest.mark.parametrize("settings", [{}, {"ROVER_WEB_ROS_ADMIN": "read-only", "ROVER_WEB_ROS_ADMIN_DENY": ["node:/x"]},
                                      {"ROVER_WEB_ROS_ADMIN_DENY": "docs"}], ids=["default", "read-only", "docs"])
def test_no_warning_for_the_default_a_read_only_admin_or_the_docs_example(app_factory, caplog, settings):
    caplog.set_level("WARNING", logger="rover_web")
    if settings.get("ROVER_WEB_ROS_ADMIN_DENY") == "docs":
        settings = {"ROVER_WEB_ROS_ADMIN_DENY": docs_example_deny()}
    app_factory(**settings)
    assert dropped_warnings(caplog) == []


def test_safety_nodes_keep_their_parameters_while_the_estop_is_engaged(client, admin_peer):
    """The default ROVER_WEB_ROS_ADMIN_SAFETY_NODES is every node."""
    wait_for_parameters(client)
    client.post("/api/estop", json={"engaged": True})
    response = client.put(f"{PEER_URL}/parameters/count", json={"value": 6})
    assert (response.status_code, response.get_json()["error"]) == (409, "estop_engaged")
    assert "ROVER_WEB_ROS_ADMIN_SAFETY_NODES" in response.get_json()["message"]
    assert wait_for_parameters(client)["count"]["value"] == 3
    assert client.post("/api/estop", json={"engaged": False}).status_code == 200
    assert client.put(f"{PEER_URL}/parameters/count", json={"value": 6}).status_code == 200
    assert wait_for_parameters(client)["count"]["value"] == 6


def test_nodes_not_listed_as_safety_nodes_may_be_tuned_during_the_estop(app_factory, admin_peer):
    client = app_factory(ROVER_WEB_ROS_ADMIN_SAFETY_NODES=["/base/*", "/estop_*"]).test_client()
    wait_for_parameters(client)
    client.post("/api/estop", json={"engaged": True})
    assert client.put(f"{PEER_URL}/parameters/count", json={"value": 8}).status_code == 200
    assert wait_for_parameters(client)["count"]["value"] == 8


def test_ros_admin_off_refuses_every_route_and_hides_the_link(app_factory, admin_peer):
    client = app_factory(ROVER_WEB_ROS_ADMIN="off").test_client()
    for method, path, body in [("GET", "/api/nodes", None), ("GET", PEER_URL + "/parameters", None),
                               ("PUT", PEER_URL + "/parameters/count", {"value": 5}),
                               ("GET", "/api/services", None), ("GET", "/api/types/std_srvs/srv/SetBool", None),
                               ("POST", "/api/services/call", {"service": "/peer_ns/set_enabled", "type": SET_BOOL}),
                               ("POST", "/api/actions/goal", {"action": "/fibonacci", "type": FIB}),
                               ("GET", "/api/actions/goals", None), ("GET", "/api/ros/log", None)]:
        response = client.open(path, method=method, json=body)
        assert (response.status_code, response.get_json()["error"]) == (403, "ros_admin_off"), (method, path)
        assert "ROVER_WEB_ROS_ADMIN=off" in response.get_json()["message"]
    page = client.get("/ros")
    assert page.status_code == 403 and "ROS admin is off" in page.get_data(as_text=True)
    assert 'href="/ros"' not in client.get("/").get_data(as_text=True)
    nothing_more(admin_peer, "called")


def test_read_only_shows_the_graph_and_sends_nothing(app_factory, admin_peer):
    client = app_factory(ROVER_WEB_ROS_ADMIN="read-only").test_client()
    assert wait_for_parameters(client)["count"]["value"] == 3
    wait_for_service(client, "/peer_ns/set_enabled")
    response = client.put(f"{PEER_URL}/parameters/count", json={"value": 5})
    assert (response.status_code, response.get_json()["error"]) == (403, "ros_admin_read_only")
    response = client.post("/api/services/call", json={"service": "/peer_ns/set_enabled", "type": SET_BOOL})
    assert (response.status_code, response.get_json()["error"]) == (403, "ros_admin_read_only")
    # Canceling only stops: still answered by the view (no such goal here).
    assert client.post("/api/actions/" + "0" * 32 + "/cancel", json={}).status_code == 404
    assert 'href="/ros"' in client.get("/").get_data(as_text=True)
    assert "read-only" in client.get("/ros").get_data(as_text=True)
    nothing_more(admin_peer, "called")
    assert wait_for_parameters(client)["count"]["value"] == 3


@pytest.mark.parametrize("action,type_name", [("/navigate_to_pose", FIB), ("/robot1/follow_waypoints", FIB),
                                              ("/go_there", "nav2_msgs/action/NavigateToPose")])
def test_navigation_goals_are_refused_with_the_routes_that_check(client, action_server, action, type_name):
    """A Fibonacci server under a navigation action's name stands for nav2 (no nav2_msgs here)."""
    peer = action_server(action)
    wait_until(lambda: any(a["name"] == action for n in client.get("/api/nodes").get_json()["nodes"]
                           for a in n["action_servers"]), 15, f"action server {action}")
    goal = {"order": 3} if type_name == FIB else {}
    response = client.post("/api/actions/goal", json={"action": action, "type": type_name, "goal": goal})
    assert (response.status_code, response.get_json()["error"]) == (403, "navigation_goal"), response.get_json()
    assert "/api/maps/<map>/goal" in response.get_json()["message"]
    assert "/api/waypoints/send" in response.get_json()["message"]
    nothing_more(peer, "accepted")
