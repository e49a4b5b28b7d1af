"""Every state-changing route, the teleop handshake and SSE, for each kind of caller.

No credentials: 401. A viewer: 403, except engaging the e-stop. An operator: 2xx, except the
admin routes (403), which an admin may use. The table must name every state-changing route the
app has, so a new route cannot be added without deciding who may call it.
"""

import pytest
import requests
import websocket

GEOJSON = {"type": "FeatureCollection", "features": [
    {"type": "Feature", "geometry": {"type": "Point", "coordinates": [-71.0, 42.0]}, "properties": {}}]}

LAYOUT = {"version": 1, "name": "roles", "cards": [{"type": "drive", "x": 0, "y": 0, "w": 4, "h": 6}]}

# (method, path, body, the least role that may, the rule it exercises). Run in this order.
REQUESTS = [
    ("POST", "/api/estop", {"engaged": True}, "viewer", "/api/estop"),
    ("POST", "/api/estop/all", {}, "viewer", "/api/estop/all"),
    ("POST", "/estop", {}, "viewer", "/estop"),  # the header's form (scripts off); engages only
    ("POST", "/api/estop", {"engaged": False}, "operator", "/api/estop"),
    ("POST", "/api/teleop", {"command": "stop"}, "operator", "/api/teleop"),
    ("POST", "/api/maps/{map}/goal", {"x": 0.0, "y": 0.0}, "operator", "/api/maps/<name>/goal"),
    ("POST", "/api/maps/{map}/initial_pose", {"x": 0.0, "y": 0.0}, "operator", "/api/maps/<name>/initial_pose"),
    ("POST", "/api/panels/drone/unlock", {}, "operator", "/api/panels/<panel_id>/unlock"),
    ("POST", "/api/panels/drone/stop", {}, "operator", "/api/panels/<panel_id>/<control_id>"),
    ("POST", "/api/panels/drone/lock", {}, "operator", "/api/panels/<panel_id>/lock"),
    ("PUT", "/api/geofence", {"type": "FeatureCollection", "features": []}, "admin", "/api/geofence"),
    ("POST", "/waypoints", {"lng": -71.0, "lat": 42.0}, "operator", "/waypoints"),
    ("POST", "/api/waypoints", {"lng": -71.001, "lat": 42.001}, "operator", "/api/waypoints"),
    ("PATCH", "/api/waypoints/{waypoint}", {"label": "dock"}, "operator", "/api/waypoints/<int:waypoint_id>"),
    ("POST", "/api/waypoints/send", {}, "operator", "/api/waypoints/send"),
    ("DELETE", "/api/waypoints/{waypoint}", None, "operator", "/api/waypoints/<int:waypoint_id>"),
    ("POST", "/api/waypoints/geojson", GEOJSON, "operator", "/api/waypoints/geojson"),
    ("DELETE", "/api/waypoints", None, "operator", "/api/waypoints"),
    ("POST", "/api/users", {"name": "new", "role": "viewer", "password": "long enough"}, "admin", "/api/users"),
    ("PATCH", "/api/users/new", {"role": "operator"}, "admin", "/api/users/<name>"),
    ("POST", "/api/tokens", {"user": "new"}, "admin", "/api/tokens"),
    ("DELETE", "/api/tokens/{token}", None, "admin", "/api/tokens/<int:token_id>"),
    ("DELETE", "/api/users/new", None, "admin", "/api/users/<name>"),
    ("PUT", "/api/nodes/nobody/parameters/x", {"value": 1}, "admin",
     "/api/nodes/<path:node>/parameters/<path:name>"),
    ("POST", "/api/services/call", {"service": "/nobody", "type": "std_srvs/srv/Trigger"}, "admin",
     "/api/services/call"),
    ("POST", "/api/actions/goal", {"action": "/nobody", "type": "test_msgs/action/Fibonacci", "goal": {"x": 1}},
     "admin", "/api/actions/goal"),
    ("POST", "/api/actions/" + "0" * 32 + "/cancel", {}, "operator", "/api/actions/<goal_id>/cancel"),
    ("POST", "/api/recordings", {"topics": "all"}, "operator", "/api/recordings"),
    ("POST", "/api/recordings/nosuch/stop", {}, "operator", "/api/recordings/<recording_id>/stop"),
    ("DELETE", "/api/recordings/nosuch", None, "admin", "/api/recordings/<recording_id>"),
    ("POST", "/api/recordings/upload", {}, "operator", "/api/recordings/upload"),
    ("POST", "/api/me/sessions/revoke", {}, "viewer", "/api/me/sessions/revoke"),  # tokens stay valid
    ("POST", "/api/camera/whep?topic=/camera/image_raw", {}, "viewer", "/api/camera/whep"),
    ("DELETE", "/api/camera/whep/nosuchsession", None, "viewer", "/api/camera/whep/<session_id>"),
    ("POST", "/api/camera/viewers/nosuchviewer/ack", {"bytes": 0}, "viewer", "/api/camera/viewers/<viewer_id>/ack"),
    ("POST", "/api/layouts", LAYOUT, "operator", "/api/layouts"),
    ("PUT", "/api/layouts/{layout}", LAYOUT, "operator", "/api/layouts/<int:layout_id>"),
    ("PUT", "/api/me/layout", {"id": 1}, "viewer", "/api/me/layout"),  # picking is not changing a layout
    ("PUT", "/api/me/preferences", {"theme": "daylight"}, "viewer", "/api/me/preferences"),  # one's own choices
    ("DELETE", "/api/layouts/{layout}", None, "operator", "/api/layouts/<int:layout_id>"),
    ("POST", "/api/nav2/goal", {"x": 0.0, "y": 0.0}, "operator", "/api/nav2/goal"),
    ("POST", "/api/nav2/route", {"mode": "follow_waypoints", "poses": [{"x": 0.0, "y": 0.0}]}, "operator",
     "/api/nav2/route"),
    ("POST", "/api/nav2/cancel", {}, "operator", "/api/nav2/cancel"),
    ("POST", "/logout", {}, "viewer", "/logout"),
]
# Routes whose success needs a ROS peer: for a caller who may use them, this answer (from the view,
# so past the role check) stands for success.
ANSWERED_WITHOUT_A_PEER = {
    "/api/nodes/<path:node>/parameters/<path:name>": (404, "unknown_node"),
    "/api/services/call": (404, "unknown_service"),
    "/api/actions/goal": (400, "unknown_field"),
    "/api/actions/<goal_id>/cancel": (404, "unknown_goal"),
    # WHEP takes an SDP body (tests/integration/camera/webrtc): JSON gets this, past the role check.
    "/api/camera/whep": (415, "unsupported_media_type"),
    "/api/camera/whep/<session_id>": (404, "unknown_session"),
    # An ack names a stream the caller opened (tests/integration/camera/test_acks.py).
    "/api/camera/viewers/<viewer_id>/ack": (404, "unknown_viewer"),
    # Stopping or deleting names a recording (tests/integration/recording/test_recording.py).
    "/api/recordings/<recording_id>/stop": (404, "not_found"),
    "/api/recordings/<recording_id>": (404, "not_found"),
    # An upload's body is the MCAP file (tests/integration/recording/test_upload.py): JSON is not one.
    "/api/recordings/upload": (422, "not_mcap"),
    # Nav2's goals need its action servers (tests/integration/nav2/); cancelling needs a goal.
    "/api/nav2/goal": (503, "no_nav2_server"),
    "/api/nav2/route": (503, "no_nav2_server"),
    "/api/nav2/cancel": (409, "no_goal"),
}
RANK = {None: -1, "viewer": 0, "operator": 1, "admin": 2}
PUBLIC = {("POST", "/login"), ("POST", "/login/estop")}  # tests/integration/estop/test_estop_all.py


def test_the_table_names_every_state_changing_route(app):
    changing = {(method, rule.rule) for rule in app.url_map.iter_rules()
                for method in rule.methods & {"POST", "PUT", "PATCH", "DELETE"}}
    covered = {(method, rule) for method, _path, _body, _role, rule in REQUESTS}
    assert changing - PUBLIC == covered


@pytest.mark.parametrize("caller", [None, "viewer", "operator", "admin"])
def test_who_may_change_what(signed_server, caller):
    headers = {"Authorization": f"Bearer {signed_server.tokens[caller]}"} if caller else {}
    url = signed_server.url
    admin = {"Authorization": f"Bearer {signed_server.tokens['admin']}"}
    first_map = requests.get(url + "/api/maps", headers=admin, timeout=5).json()["maps"][0]["name"]
    ids = {"map": first_map, "waypoint": 999, "token": 999, "layout": 999}
    for method, path, body, least, rule in REQUESTS:
        if "{waypoint}" in path and RANK[caller] >= RANK["operator"]:
            mission = requests.get(url + "/api/waypoints", headers=admin, timeout=5).json()
            ids["waypoint"] = mission["waypoints"][-1]["id"]
        if "{layout}" in path and RANK[caller] >= RANK["operator"]:
            ids["layout"] = requests.get(url + "/api/layouts", headers=admin, timeout=5).json()["layouts"][-1]["id"]
        if "{token}" in path and RANK[caller] >= RANK["admin"]:
            ids["token"] = requests.get(url + "/api/tokens", headers=admin, timeout=5).json()["tokens"][-1]["id"]
        response = requests.request(method, url + path.format(**ids), json=body, headers=headers, timeout=10,
                                    allow_redirects=False)
        what = f"{caller} {method} {path}: {response.status_code} {response.text[:200]}"
        if caller is None:
            assert response.status_code == 401 and response.json()["error"] == "unauthenticated", what
        elif RANK[caller] < RANK[least]:
            assert response.status_code == 403 and response.json()["error"] == "forbidden", what
        elif rule in ANSWERED_WITHOUT_A_PEER:
            assert (response.status_code, response.json()["error"]) == ANSWERED_WITHOUT_A_PEER[rule], what
        else:
            assert 200 <= response.status_code < 300, what


@pytest.mark.parametrize("caller,status", [(None, 401), ("viewer", 403), ("operator", 101)])
def test_the_teleop_handshake(signed_server, caller, status):
    header = [f"Authorization: Bearer {signed_server.tokens[caller]}"] if caller else []
    ws_url = signed_server.url.replace("http://", "ws://") + "/ws/teleop"
    if status == 101:
        ws = websocket.create_connection(ws_url, header=header, timeout=5)
        assert ws.getstatus() == 101
        ws.close()
        return
    with pytest.raises(websocket.WebSocketBadStatusException) as refused:
        websocket.create_connection(ws_url, header=header, timeout=5)
    assert refused.value.status_code == status


@pytest.mark.parametrize("caller,status", [(None, 401), ("viewer", 200), ("operator", 200)])
def test_the_event_stream(signed_server, caller, status):
    headers = {"Authorization": f"Bearer {signed_server.tokens[caller]}"} if caller else {}
    with requests.get(signed_server.url + "/api/events?channels=status", headers=headers, stream=True,
                      timeout=5) as response:
        assert response.status_code == status
