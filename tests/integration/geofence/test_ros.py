"""The geofence with real ROS peers in other processes: refused commands are never published, and a
/fix outside the fence raises the `geofence` event and, when configured, the e-stop."""

import time

import requests

from tests.support.geofence_helpers import FENCE, IN_KEEP_OUT, INSIDE, OUTSIDE
from tests.support.waypoint_helpers import FLOAT64_MULTI_ARRAY, warm_up_topic

NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"
BOOL = "std_msgs/msg/Bool"


def put_fence(url, doc=FENCE):
    requests.put(url + "/api/geofence", json=doc, timeout=5).raise_for_status()


def test_refused_waypoints_and_missions_are_not_published(live_server, ros_peer):
    url = live_server.url
    put_fence(url)
    peer = ros_peer("geofence_listener")
    peer.subscribe("/waypoints", FLOAT64_MULTI_ARRAY)
    peer.subscribe("/mission", FLOAT64_MULTI_ARRAY)
    peer.wait_match("/waypoints")
    peer.wait_match("/mission")
    warm_up_topic(url, peer)

    for route in ("/waypoints", "/api/waypoints"):
        for lng, lat in (OUTSIDE, IN_KEEP_OUT):
            r = requests.post(url + route, json={"lng": lng, "lat": lat}, timeout=5)
            assert r.status_code == 422 and r.json()["error"] == "outside_geofence"
    sentinel = requests.post(url + "/api/waypoints", json={"lng": INSIDE[0], "lat": INSIDE[1]}, timeout=5)
    assert sentinel.status_code == 201
    peer.wait_for("/waypoints", lambda m: m["data"] == list(INSIDE))
    time.sleep(0.3)
    assert [m["msg"]["data"] for m in peer.received("/waypoints")] == [list(INSIDE)]

    # The mission topic warmed up with an allowed mission first, so a refused send that had been
    # published could not hide behind discovery.
    deadline = time.monotonic() + 15
    while not peer.received("/mission"):
        assert time.monotonic() < deadline, "the subscriber never heard /mission"
        assert requests.post(url + "/api/waypoints/send", json={}, timeout=5).ok
        time.sleep(0.1)
    time.sleep(0.2)
    peer.clear("/mission")
    far = requests.post(url + "/api/waypoints", json={"lng": 0.9, "lat": 0.9}, timeout=5).json()["waypoint"]
    refused = requests.post(url + "/api/waypoints/send", json={}, timeout=5)  # (0.3,0.3)->(0.9,0.9): the dock
    assert refused.status_code == 422 and refused.json()["reason"] == "leg_crosses_keep_out"
    requests.patch(f"{url}/api/waypoints/{far['id']}", json={"lng": 0.9, "lat": 0.3}, timeout=5).raise_for_status()
    assert requests.post(url + "/api/waypoints/send", json={}, timeout=5).ok
    peer.wait_for("/mission")
    time.sleep(0.3)
    assert [m["msg"]["data"] for m in peer.received("/mission")] == [[0.3, 0.3, 0.9, 0.3]]


def fix(lng, lat):
    return {"header": {"frame_id": "gps"}, "status": {"status": 0, "service": 1},
            "latitude": lat, "longitude": lng, "altitude": 2.0, "position_covariance_type": 0}


def gps_peer(ros_peer, server):
    peer = ros_peer("gps")
    peer.advertise("/fix", NAV_SAT_FIX)
    peer.wait_match("/fix")
    deadline = time.monotonic() + 10
    while (server.rover.hub.latest("geofence") or {}).get("state") != "inside":
        assert time.monotonic() < deadline, "the app never placed the robot inside the fence"
        peer.publish("/fix", fix(*INSIDE))
        time.sleep(0.05)
    return peer


def test_a_breach_raises_the_event_and_engages_the_e_stop_when_configured(live_server_factory, ros_peer,
                                                                         sse_client):
    server = live_server_factory(ROVER_WEB_GEOFENCE_ESTOP=True)
    put_fence(server.url)
    flag = ros_peer("safety")
    flag.subscribe("/e_stop", BOOL, qos="latched")
    gps = gps_peer(ros_peer, server)
    stream = sse_client(server.url + "/api/events?channels=geofence,estop")
    stream.wait_for("geofence", lambda d: d["state"] == "inside")
    assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is False

    gps.publish("/fix", fix(*OUTSIDE))
    left = stream.wait_for("geofence", lambda d: d["state"] == "outside")["json"]
    assert (left["lng"], left["lat"]) == OUTSIDE and "keep-in" in left["message"]
    engaged = stream.wait_for("estop", lambda d: d["engaged"])["json"]
    assert engaged["by"] == "geofence breach" and engaged["via"] == "geofence"
    flag.wait_for("/e_stop", lambda m: m["data"] is True)

    # Released by the operator while still outside (to drive back in): not engaged again for the
    # same breach; back inside is an event of its own.
    requests.post(server.url + "/api/estop", json={"engaged": False}, timeout=5).raise_for_status()
    gps.publish("/fix", fix(OUTSIDE[0] + 0.01, OUTSIDE[1]))
    time.sleep(0.5)
    assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is False
    gps.publish("/fix", fix(*INSIDE))
    stream.wait_for("geofence", lambda d: d["state"] == "inside" and d["since"] > left["since"])
    gps.publish("/fix", fix(*IN_KEEP_OUT))  # a keep-out is a breach too
    again = stream.wait_for("geofence", lambda d: d["state"] == "outside" and d["since"] > left["since"])["json"]
    assert "'dock'" in again["message"]
    stream.wait_for("estop", lambda d: d["engaged"] and d["since"] > engaged["since"])


def test_without_the_setting_a_breach_is_only_an_event(live_server, ros_peer, sse_client):
    put_fence(live_server.url)
    gps = gps_peer(ros_peer, live_server)
    stream = sse_client(live_server.url + "/api/events?channels=geofence")
    gps.publish("/fix", fix(*OUTSIDE))
    state = stream.wait_for("geofence", lambda d: d["state"] == "outside")["json"]
    assert state["estop_on_breach"] is False
    time.sleep(0.3)
    assert requests.get(live_server.url + "/api/estop", timeout=5).json()["engaged"] is False
    page = requests.get(live_server.url + "/waypoints", timeout=5).text
    assert 'id="geofence-banner"' in page and "left the geofence" in page


def test_the_simulators_fix_inside_the_demo_fence_then_a_fence_that_excludes_it_is_a_breach(
        live_server_factory, sim_process, sse_client):
    from rover_web.demo import DEMO_GEOFENCE
    from tests.support.geofence_helpers import area, collection, square

    server = live_server_factory(ROVER_WEB_GEOFENCE_FILE=DEMO_GEOFENCE, ROVER_WEB_GEOFENCE_ESTOP=True)
    stream = sse_client(server.url + "/api/events?channels=geofence,estop")
    sim_process("--only", "rover")
    inside = stream.wait_for("geofence", lambda d: d["state"] == "inside", timeout=20)["json"]
    assert inside["areas"] == 2 and inside["revision"] == 1
    # Move the keep-in 2 km east: the simulated rover, parked at its start, is now outside it.
    put_fence(server.url, collection(area("keep_in", square(-82.43, 27.36, -82.42, 27.39))))
    left = stream.wait_for("geofence", lambda d: d["state"] == "outside", timeout=10)["json"]
    assert left["lng"] < -82.44 and left["revision"] == 2
    assert stream.wait_for("estop", lambda d: d["engaged"])["json"]["by"] == "geofence breach"
