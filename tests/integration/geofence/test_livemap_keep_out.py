"""A LiveMap goal inside a floorplan's keep-out area is 422 and never reaches a subscriber in another
process; a goal beside it does."""

import time
from urllib.parse import quote

import pytest

from tests.integration.livemap.test_api import GOAL, warm_up_goal

B = quote("Science Hall Basement")


@pytest.mark.ros
def test_a_goal_in_a_keep_out_area_is_refused_and_not_published(client, ros_peer):
    peer = ros_peer()
    peer.subscribe("/goal_pose", GOAL)
    peer.wait_match("/goal_pose")
    warm_up_goal(client, peer)
    before = client.get(f"/api/maps/{B}").json["map_parameters"]["goal_pose"]
    for x, y in ((35.0, 2.0), (34.0, 2.0)):  # inside the electrical room, on its wall
        r = client.post(f"/api/maps/{B}/goal", json={"x": x, "y": y})
        assert r.status_code == 422
        assert r.json["error"] == "outside_geofence" and r.json["reason"] == "inside_keep_out"
        assert "'electrical room'" in r.json["message"]
    assert client.get(f"/api/maps/{B}").json["map_parameters"]["goal_pose"] == before
    assert client.post(f"/api/maps/{B}/goal", json={"x": 33.0, "y": 2.0}).status_code == 200  # the sentinel
    peer.wait_for("/goal_pose", lambda m: m["pose"]["position"]["x"] == 33.0)
    time.sleep(0.3)
    assert [m["msg"]["pose"]["position"]["x"] for m in peer.received("/goal_pose")] == [33.0]
    maps = client.get("/api/maps").json["maps"]
    assert maps[0]["keep_out"][0]["name"] == "electrical room"
