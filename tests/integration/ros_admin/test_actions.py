"""Action goals to another process: accepted, feedback and result as SSE, canceled, canceled on e-stop."""

import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

FIB = "test_msgs/action/Fibonacci"


def ready(server, peer, action="/fibonacci"):
    """The peer once the app's graph lists its action server (discovery takes a moment)."""
    def listed():
        nodes = requests.get(server.url + "/api/nodes", timeout=5).json()["nodes"]
        return any(a["name"] == action for n in nodes for a in n["action_servers"])
    wait_until(listed, 15, f"action server {action}")
    return peer


def send(server, order, action="/fibonacci"):
    return requests.post(server.url + "/api/actions/goal", json={"action": action, "type": FIB,
                                                                 "goal": {"order": order}}, timeout=15)


def test_a_goal_streams_feedback_status_and_result(live_server, action_peer, sse_client):
    ready(live_server, action_peer())
    response = send(live_server, 5)
    assert response.status_code == 200, response.text
    goal = response.json()
    assert len(goal["goal_id"]) == 32 and goal["status"] in ("accepted", "executing", "succeeded")
    stream = sse_client(f"{live_server.url}/api/actions/{goal['goal_id']}/events")
    result = stream.wait_for("result", timeout=15)["json"]
    assert result == {"goal_id": goal["goal_id"], "status": "succeeded",
                      "result": {"sequence": [0, 1, 1, 2, 3, 5]}}
    first = stream.of("status")[0]["json"]
    assert first["goal_id"] == goal["goal_id"] and first["action"] == "/fibonacci"
    # Feedback was the sequence growing (conflated: a late stream may have seen only the last).
    feedback = [e["json"]["feedback"]["sequence"] for e in stream.of("feedback")] or [first["feedback"]["sequence"]]
    assert all(seq == [0, 1, 1, 2, 3, 5][:len(seq)] for seq in feedback)
    wait_until(stream.closed.is_set, 5, "the stream to end after the result")
    listed = requests.get(live_server.url + "/api/actions/goals", timeout=5).json()["goals"]
    assert [(g["goal_id"], g["status"]) for g in listed] == [(goal["goal_id"], "succeeded")]


def test_a_goal_is_canceled(live_server, action_peer, sse_client):
    peer = ready(live_server, action_peer())
    goal = send(live_server, 1000).json()
    peer.wait("accepted")
    stream = sse_client(f"{live_server.url}/api/actions/{goal['goal_id']}/events")
    stream.wait_for("feedback", timeout=10)
    response = requests.post(f"{live_server.url}/api/actions/{goal['goal_id']}/cancel", json={}, timeout=10)
    assert response.status_code == 200 and response.json()["cancel"] == "canceling"
    peer.wait("canceled")
    assert stream.wait_for("result", timeout=10)["json"]["status"] == "canceled"


def test_goals_sent_from_here_are_canceled_when_the_estop_engages(live_server, action_peer, sse_client):
    peer = ready(live_server, action_peer())
    goal = send(live_server, 1000).json()
    peer.wait("accepted")
    stream = sse_client(f"{live_server.url}/api/actions/{goal['goal_id']}/events")
    requests.post(live_server.url + "/api/estop", json={"engaged": True}, timeout=5)
    peer.wait("canceled")
    assert stream.wait_for("result", timeout=10)["json"]["status"] == "canceled"
    response = send(live_server, 3)
    assert (response.status_code, response.json()["error"]) == (409, "estop_engaged")
    entries = requests.get(live_server.url + "/api/ros/log", timeout=5).json()["entries"]
    assert [(e["control"], e["result"], e["reason"]) for e in entries[:2]] == [
        ("send_goal", "refused", "estop_engaged"), ("cancel_goal", "sent", "e-stop engaged")]


def test_refused_goals(live_server, action_peer):
    url = live_server.url
    assert send(live_server, 3, action="/nobody").status_code == 504
    ready(live_server, action_peer())
    bad = requests.post(url + "/api/actions/goal", json={"action": "/fibonacci", "type": FIB,
                                                         "goal": {"order": 2**40}}, timeout=10)
    assert (bad.status_code, bad.json()["error"]) == (400, "out_of_range") and "goal.order" in bad.json()["message"]
    bad = requests.post(url + "/api/actions/goal", json={"action": "/fibonacci", "type": FIB,
                                                         "goal": {"steps": 1}}, timeout=10)
    assert (bad.status_code, bad.json()["error"]) == (400, "unknown_field")
    bad = requests.post(url + "/api/actions/goal", json={"action": "/fibonacci", "type": "os/action/Thing"},
                        timeout=10)
    assert bad.status_code == 422
    assert requests.post(url + "/api/actions/" + "0" * 32 + "/cancel", json={}, timeout=5).status_code == 404
    assert requests.post(url + "/api/actions/xyz/cancel", json={}, timeout=5).status_code == 400
    assert requests.get(url + "/api/actions/" + "0" * 32 + "/events", timeout=5).status_code == 404
