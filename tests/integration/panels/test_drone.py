"""The drone panel against the simulated drone in its own process, and commands that never go stale."""

import re
import time

import requests

from tests.support.panels_support import (
    STRING,
    drone_sim,  # noqa: F401 (fixture)
    feed_status,
    log_entries,
    post,
    wait_display,
    wait_subscribers,
)

INT8 = "std_msgs/msg/Int8"


def status_of(event) -> str:
    return event["json"]["panels"]["drone"]["displays"]["status"]["value"]


def test_take_off_return_and_refusals_with_the_simulated_drone(live_server, drone_sim, ros_peer, sse_client):  # noqa: F811
    sim = drone_sim("--drone-transition-s", "1.5", "--drone-rate-hz", "10")
    url = live_server.url
    listener = ros_peer("listener")
    listener.subscribe("/control_phase", INT8)
    listener.subscribe("/flight_destination", INT8)
    listener.wait_match("/control_phase")
    listener.wait_match("/flight_destination")
    wait_display(url, "drone", "status", "Standby")
    wait_subscribers(url, "drone", {"takeoff": 2, "destination": 2})  # the drone and the listener hear commands
    stream = sse_client(url + "/api/events?channels=panel,panel_log")

    # Locked: refused, nothing published.
    response = post(url, "drone/takeoff", {"confirmed": True})
    assert response.status_code == 409 and response.json()["error"] == "locked"
    assert post(url, "drone/unlock").status_code == 200

    # Take off: Standby -> Flying -> Hovering, on the API, on SSE and on the page.
    sent_at = time.monotonic()
    response = post(url, "drone/takeoff", {"confirmed": True})
    assert response.status_code == 200 and response.json()["value"] == 1
    assert listener.wait_for("/control_phase")["msg"]["data"] == 1
    flying = stream.wait_for("panel", lambda d: d["panels"]["drone"]["displays"]["status"]["value"] == "Flying")
    assert flying["json"]["panels"]["drone"]["light"] == "red"
    assert flying["json"]["panels"]["drone"]["controls"]["takeoff"]["enabled"] is False

    # Take off while Flying: 409 with the reason, and nothing on /control_phase.
    listener.clear("/control_phase")
    response = post(url, "drone/takeoff", {"confirmed": True})
    assert response.status_code == 409
    assert response.json() == {"error": "not_allowed",
                               "message": "Take off is only allowed when Status is Standby; it is Flying"}
    assert requests.get(url + "/api/panels/drone", timeout=5).json()["displays"][0]["value"] == "Flying"

    hovering = stream.wait_for("panel", lambda d: d["panels"]["drone"]["displays"]["status"]["value"] == "Hovering")
    assert hovering["t"] - sent_at >= 1.0  # the drone took its transition time
    view = hovering["json"]["panels"]["drone"]
    assert view["controls"]["return"]["enabled"] and view["controls"]["destination"]["enabled"]
    assert not view["controls"]["takeoff"]["enabled"] and view["controls"]["stop"]["enabled"]
    wait_display(url, "drone", "status", "Hovering")
    assert listener.received("/control_phase") == []  # the refused take off never went out
    height = wait_display(url, "drone", "flight_height", 5)
    assert height["text"] == "5 m"
    page = requests.get(url + "/panels/drone", timeout=5).text
    assert re.search(r'data-display="status"[^>]*>\s*<span class="cp-text">Hovering</span>', page)
    assert re.search(r'data-control="takeoff"[^>]*disabled', page)
    assert not re.search(r'data-control="return"[^>]*disabled', page)
    assert 'data-light="red"' in page

    # Int8 out of range: 400, nothing on /flight_destination.
    response = post(url, "drone/destination", {"value": 200, "confirmed": True})
    assert response.status_code == 400 and response.json()["error"] == "out_of_range"

    # A destination: Flying, then Hovering above that tag.
    assert post(url, "drone/destination", {"value": 6, "confirmed": True}).status_code == 200
    listener.wait_for("/flight_destination", lambda m: m["data"] == 6)
    assert [m["msg"]["data"] for m in listener.received("/flight_destination")] == [6]  # not the 200
    wait_display(url, "drone", "tag", 6)
    wait_display(url, "drone", "status", "Hovering")
    location = wait_display(url, "drone", "location", {"x": 4.0, "y": 4.0, "z": 5.0})
    assert location["text"] == "x 4.0 · y 4.0 · z 5.0 m"

    # Return: Flying, then Standby on the pad; the light goes green again.
    assert post(url, "drone/return", {"confirmed": True}).status_code == 200
    assert listener.wait_for("/control_phase", lambda m: m["data"] == 2)
    stream.wait_for("panel", lambda d: d["panels"]["drone"]["displays"]["status"]["value"] == "Standby"
                    and d["panels"]["drone"]["light"] == "green")
    wait_display(url, "drone", "tag", 0)

    expected = [("takeoff", "refused"), ("unlock", "unlocked"), ("takeoff", "sent"), ("takeoff", "refused"),
                ("destination", "invalid"), ("destination", "sent"), ("return", "sent")]
    assert [(e["control"], e["result"]) for e in reversed(log_entries(url))] == expected
    assert [(e["json"]["control"], e["json"]["result"]) for e in stream.of("panel_log")] == expected
    assert "taking off to 5 m" in "".join(sim.output)


def test_a_late_subscriber_never_receives_an_old_command(live_server, ros_peer):
    url = live_server.url
    drone = ros_peer("fake_drone")
    drone.advertise("/status", STRING)
    on_time = ros_peer("on_time")
    on_time.subscribe("/control_phase", INT8)
    on_time.wait_match("/control_phase")
    drone.wait_match("/status")
    feed_status(drone, url, "Standby")
    assert post(url, "drone/unlock").status_code == 200
    assert post(url, "drone/takeoff", {"confirmed": True}).status_code == 200
    assert on_time.wait_for("/control_phase")["msg"]["data"] == 1  # it was published

    # Subscribers that join afterwards, one asking for history (transient local), one not.
    late = ros_peer("late_volatile")
    late.subscribe("/control_phase", INT8, qos="default")
    history = ros_peer("late_history")
    history.subscribe("/control_phase", INT8, qos="latched")
    late.wait_match("/control_phase")
    time.sleep(1.5)  # ample time for a stored sample to be delivered
    assert late.received("/control_phase") == []
    assert history.received("/control_phase") == []

    # The late volatile subscriber is connected: it gets the next command, and only that one.
    assert post(url, "drone/stop").status_code == 200
    assert late.wait_for("/control_phase")["msg"]["data"] == 0
    time.sleep(0.3)
    assert [m["msg"]["data"] for m in late.received("/control_phase")] == [0]
    assert history.received("/control_phase") == []
