"""Waypoints over ROS, checked by real rclpy subscribers and publishers in other processes."""

import json
import math
import subprocess
import threading
import time

import requests

from tests.support.waypoint_helpers import FLOAT64_MULTI_ARRAY, warm_up_topic

NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"


def test_the_seed_curl_call_publishes_lng_first(server_process, ros_peer):
    server = server_process().start()
    peer = ros_peer("waypoint_listener")
    peer.subscribe("/waypoints", FLOAT64_MULTI_ARRAY)
    peer.wait_match("/waypoints")
    warm_up_topic(server.url, peer)
    # Exactly the seeds' command line, with only the port changed.
    out = subprocess.run(["curl", "-sS", "-X", "POST", f"{server.url}/waypoints",
                          "-H", "Content-Type: application/json",
                          "-d", '{"lng": 1.0, "lat": 2.0}', "-w", "\n%{http_code}"],
                         capture_output=True, text=True, timeout=30, check=True).stdout
    body, status = out.rsplit("\n", 1)
    assert status == "200"
    reply = json.loads(body)
    assert reply["status"] == "success" and reply["message"] == "Waypoint received"
    assert (reply["waypoint"]["lng"], reply["waypoint"]["lat"]) == (1.0, 2.0)
    msg = peer.wait_for("/waypoints", timeout=10)["msg"]
    assert msg["data"] == [1.0, 2.0]  # lng first, exact values
    assert msg["layout"] == {"dim": [], "data_offset": 0}  # as `ros2 topic echo` showed for the seeds
    time.sleep(0.3)
    assert len(peer.received("/waypoints")) == 1
    listed = requests.get(server.url + "/api/waypoints", timeout=5).json()
    assert [(w["lng"], w["lat"]) for w in listed["waypoints"]] == [(1.0, 2.0)]


def test_concurrent_adds_reach_the_topic_in_mission_order(live_server, ros_peer):
    url = live_server.url
    peer = ros_peer("order_listener")
    peer.subscribe("/waypoints", FLOAT64_MULTI_ARRAY, qos=1000)
    peer.wait_match("/waypoints")
    warm_up_topic(url, peer)

    def client(c):
        session = requests.Session()
        for i in range(25):
            route = "/waypoints" if i % 2 else "/api/waypoints"
            assert session.post(url + route, json={"lng": c + i / 100, "lat": -c}, timeout=10).ok

    threads = [threading.Thread(target=client, args=(c,)) for c in range(1, 9)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(30)
    stored = [[w["lng"], w["lat"]] for w in requests.get(url + "/api/waypoints", timeout=5).json()["waypoints"]]
    assert len(stored) == 200
    deadline = time.monotonic() + 10
    while len(peer.received("/waypoints")) < 200 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert [m["msg"]["data"] for m in peer.received("/waypoints")] == stored


def test_send_mission_is_one_n_by_2_array_in_mission_order(live_server, ros_peer):
    url = live_server.url
    peer = ros_peer("mission_listener")
    peer.subscribe("/mission", FLOAT64_MULTI_ARRAY)
    peer.wait_match("/mission")
    a = requests.post(url + "/api/waypoints", json={"lng": -82.451, "lat": 27.371}, timeout=5).json()["waypoint"]
    b = requests.post(url + "/api/waypoints", json={"lng": -82.452, "lat": 27.372}, timeout=5).json()["waypoint"]
    c = requests.post(url + "/waypoints", json={"lng": -82.453, "lat": 27.373}, timeout=5).json()["waypoint"]
    assert requests.patch(f"{url}/api/waypoints/{c['id']}", json={"index": 0}, timeout=5).ok
    deadline = time.monotonic() + 15
    while not peer.received("/mission"):  # discovery warm-up: the same mission, until heard once
        assert time.monotonic() < deadline
        assert requests.post(url + "/api/waypoints/send", json={}, timeout=5).ok
        time.sleep(0.1)
    time.sleep(0.2)
    peer.clear("/mission")
    revision = requests.get(url + "/api/waypoints", timeout=5).json()["revision"]
    sent = requests.post(url + "/api/waypoints/send", json={"revision": revision}, timeout=5)
    assert sent.status_code == 200 and sent.json()["sent"] == 3 and sent.json()["topic"] == "/mission"
    msg = peer.wait_for("/mission")["msg"]
    assert msg["layout"] == {"dim": [{"label": "waypoints", "size": 3, "stride": 6},
                                     {"label": "lng_lat", "size": 2, "stride": 2}], "data_offset": 0}
    assert msg["data"] == [c["lng"], c["lat"], a["lng"], a["lat"], b["lng"], b["lat"]]

    # Refused sends publish nothing: a stale revision, then an empty mission.
    stale = requests.post(url + "/api/waypoints/send", json={"revision": revision - 1}, timeout=5)
    assert stale.status_code == 409 and stale.json()["error"] == "mission_changed"
    requests.delete(url + "/api/waypoints", timeout=5)
    empty = requests.post(url + "/api/waypoints/send", json={}, timeout=5)
    assert empty.status_code == 409 and empty.json()["error"] == "empty_mission"
    requests.post(url + "/api/waypoints", json={"lng": 10.0, "lat": 20.0}, timeout=5)
    assert requests.post(url + "/api/waypoints/send", json={}, timeout=5).ok
    nxt = peer.wait_for("/mission", lambda m: m["data"] != msg["data"])["msg"]
    assert nxt["data"] == [10.0, 20.0] and nxt["layout"]["dim"][0]["size"] == 1
    assert len(peer.received("/mission")) == 2  # the sentinel came right after the first: nothing between


def fix(lat, lng, status=0):
    return {"header": {"frame_id": "gps"}, "status": {"status": status, "service": 1},
            "latitude": lat, "longitude": lng, "altitude": 2.0, "position_covariance_type": 2,
            "position_covariance": [0.25, 0, 0, 0, 0.25, 0, 0, 0, 1.0]}


def test_fix_reaches_the_map_channel_and_no_lock_is_not_plotted(live_server, ros_peer, sse_client):
    peer = ros_peer("gps")
    peer.advertise("/fix", NAV_SAT_FIX)
    peer.wait_match("/fix")
    stream = sse_client(live_server.url + "/api/events?channels=fix")
    deadline = time.monotonic() + 10
    while live_server.rover.hub.latest("fix") is None:
        assert time.monotonic() < deadline, "the app never received /fix"
        peer.publish("/fix", fix(27.37, -82.45))
        time.sleep(0.05)
    peer.publish("/fix", fix(27.3742443, -82.4500873))
    good = stream.wait_for("fix", lambda d: d["fix"] and d["lat"] == 27.3742443)["json"]
    assert good["lng"] == -82.4500873 and good["accuracy_m"] == 0.5 and good["alt"] == 2.0
    assert good["track"][-1] == [-82.4500873, 27.3742443]

    time.sleep(0.25)  # past the channel's throttle interval, so each state below is its own frame
    peer.publish("/fix", fix(0.0, 0.0, status=-1))  # no lock: receivers often say 0, 0
    lost = stream.wait_for("fix", lambda d: not d["fix"])["json"]
    assert lost["reason"] == "no satellite lock" and lost["lat"] is None and lost["lng"] is None
    assert [0.0, 0.0] not in lost["track"] and lost["track"] == good["track"]

    time.sleep(0.25)
    peer.publish("/fix", fix(math.nan, -82.45))
    time.sleep(0.25)
    broken = live_server.rover.hub.latest("fix")
    assert broken["fix"] is False and "finite" in broken["reason"] and broken["track"] == good["track"]
    status = requests.get(live_server.url + "/api/status", timeout=5).json()
    assert any(t["topic"] == "/fix" and t["count"] > 0 for t in status["topics"])
