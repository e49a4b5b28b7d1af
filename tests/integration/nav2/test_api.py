"""Nav2's routes without a Nav2: bad input is refused with 4xx JSON before anything is sent, keep-out
areas and the map's edges are enforced, and no server is a 503 that says so."""

import pytest

from rover_web.nav2 import msgs

pytestmark = pytest.mark.ros

B = "Science Hall Basement"


@pytest.mark.parametrize("body, code", [
    ({}, "missing_field"),
    ({"x": 1.0}, "missing_field"),
    ({"x": "1", "y": 2.0}, "bad_type"),
    ({"x": 1.0, "y": 2.0, "z": 3.0}, "unknown_field"),
    ({"x": 1.0, "y": 2.0, "yaw": True}, "bad_type"),
    ({"x": 1.0, "y": 2.0, "map": 7}, "bad_type"),
])
def test_a_bad_goal_is_a_400_naming_what_is_wrong(client, body, code):
    reply = client.post("/api/nav2/goal", json=body)
    assert reply.status_code == 400 and reply.json["error"] == code, reply.json


def test_non_finite_numbers_are_refused(client):
    reply = client.post("/api/nav2/goal", data='{"x": NaN, "y": 1}', content_type="application/json")
    assert reply.status_code == 400 and reply.json["error"] == "non_finite"


@pytest.mark.parametrize("body, code", [
    ({"mode": "through_poses"}, "missing_field"),
    ({"mode": "around", "poses": [{"x": 1.0, "y": 1.0}]}, "bad_value"),
    ({"mode": "through_poses", "poses": []}, "bad_value"),
    ({"mode": "through_poses", "poses": [[1, 2]]}, "bad_type"),
    ({"mode": "follow_waypoints", "poses": [{"x": 1.0, "y": 1.0}, {"x": 1.0}]}, "missing_field"),
    ({"mode": "follow_waypoints", "poses": [{"x": 1.0, "y": 1.0, "w": 1}]}, "unknown_field"),
])
def test_a_bad_route_is_a_400(client, body, code):
    reply = client.post("/api/nav2/route", json=body)
    assert reply.status_code == 400 and reply.json["error"] == code, reply.json


def test_too_many_poses_are_refused(app_factory):
    client = app_factory(ROVER_WEB_NAV2_MAX_POSES=2).test_client()
    reply = client.post("/api/nav2/route", json={"mode": "through_poses", "poses": [{"x": 1.0, "y": 1.0}] * 3})
    assert reply.status_code == 400 and "1 to 2 poses" in reply.json["message"]


def test_the_map_and_its_keep_out_areas_are_checked_before_anything_is_sent(client):
    reply = client.post("/api/nav2/goal", json={"x": 500.0, "y": 1.0})
    assert reply.status_code == 400 and reply.json["error"] == "outside_map"
    reply = client.post("/api/nav2/goal", json={"map": "nowhere", "x": 1.0, "y": 1.0})
    assert reply.status_code == 404 and reply.json["error"] == "unknown_map"
    reply = client.post("/api/nav2/route", json={"map": B, "mode": "follow_waypoints",
                                                 "poses": [{"x": 4.0, "y": 5.0}, {"x": 36.0, "y": 1.0}]})
    assert reply.status_code == 422
    assert reply.json["error"] == "outside_geofence" and reply.json["index"] == 1
    assert reply.json["name"] == "electrical room"
    assert client.get("/api/nav2").json["goal"] is None


def test_the_estop_refuses_goals_with_409(client):
    assert client.post("/api/estop", json={"engaged": True}).status_code == 200
    reply = client.post("/api/nav2/goal", json={"x": 4.0, "y": 5.0})
    assert reply.status_code == 409 and reply.json["error"] == "estop_engaged"


def test_no_nav2_server_is_a_503_and_nothing_to_cancel_a_409(client):
    pytest.importorskip("nav2_msgs.action")
    state = client.get("/api/nav2").json
    assert state["available"] and state["goal_via"] == "topic"  # auto, and no server answers
    assert not any(s["ready"] for s in state["servers"].values())
    reply = client.post("/api/nav2/goal", json={"x": 4.0, "y": 5.0})
    assert reply.status_code == 503 and reply.json["error"] == "no_nav2_server"
    assert "is Nav2 running" in reply.json["message"]
    reply = client.post("/api/nav2/cancel", json={})
    assert reply.status_code == 409 and reply.json["error"] == "no_goal"


def test_goal_mode_topic_keeps_livemap_on_the_goal_topic(app_factory):
    client = app_factory(ROVER_WEB_NAV2_GOAL_MODE="topic").test_client()
    assert client.get("/api/nav2").json["goal_via"] == "topic"
    assert 'data-via="topic"' in client.get(f"/livemap/{B}").get_data(as_text=True)


def test_nav2s_error_codes_are_named():
    pytest.importorskip("nav2_msgs.action")
    assert msgs.error_name(0) == "NONE"
    assert msgs.error_name(206) == "GOAL_OCCUPIED" and msgs.error_name(208) == "NO_VALID_PATH"
    assert msgs.error_name(105) == "FAILED_TO_MAKE_PROGRESS"
    assert msgs.error_name(601) == "TASK_EXECUTOR_FAILED"  # from nav2_msgs' FollowWaypoints itself
    assert msgs.error_name(12345) is None
