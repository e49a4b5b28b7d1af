"""The replay view's timeline: a recording's GPS track, /rosout lines and audit trail, decoded on the
server from the file, with the time of each; nothing is published."""

from __future__ import annotations

import requests

from tests.support.waiting import wait_until

from .helpers import start, status, stop, wait_listed

FIX = "sensor_msgs/msg/NavSatFix"


def record_a_short_run(server, peer) -> str:
    peer.advertise("/tl/fix", FIX)
    wait_listed(server, "/tl/fix")
    wait_listed(server, "/rosout")
    started = start(server, {"topics": ["/tl/fix", "/rosout"], "name": "timeline"})
    peer.wait_match("/tl/fix", 1)
    for i in range(5):
        peer.publish("/tl/fix", {"latitude": 27.37 + i * 1e-4, "longitude": -82.45 - i * 1e-4, "status": {"status": 0}})
    peer.log("thruster two hot", "warning")
    assert requests.post(server.url + "/api/estop", json={"engaged": True, "by": "carol"}, timeout=5).ok
    wait_until(lambda: (c := status(server, started["id"])["counts"]).get("/tl/fix") == 5 and c.get("/rosout", 0) >= 1,
               10, "the fixes and the log line written")
    stop(server, started["id"])
    return started["id"]


def test_the_timeline_has_the_track_the_logs_and_who_did_what_in_time_order(live_server, ros_peer):
    recording_id = record_a_short_run(live_server, ros_peer("timeline_peer"))
    answer = requests.get(f"{live_server.url}/api/recordings/{recording_id}/timeline", timeout=10)
    assert answer.status_code == 200, answer.text
    timeline = answer.json()
    assert timeline["complete"] is True and timeline["start"] <= timeline["end"]
    fixes = timeline["series"]["fix"]["/tl/fix"]
    assert [(round(p["lat"], 6), round(p["lng"], 6)) for p in fixes] == \
           [(round(27.37 + i * 1e-4, 6), round(-82.45 - i * 1e-4, 6)) for i in range(5)]
    assert any(line["msg"] == "thruster two hot" and line["level"] == "WARN" for line in timeline["logs"])
    assert ("estop.engage", "carol") in [(r["action"], r["by"]) for r in timeline["audit"]]
    times = [p["t"] for p in fixes]
    assert times == sorted(times) and timeline["start"] <= times[0] and times[-1] <= timeline["end"]
    # The page that shows it.
    page = requests.get(f"{live_server.url}/recordings/{recording_id}/replay", timeout=5)
    assert page.status_code == 200 and "replay.js" in page.text
    assert requests.get(f"{live_server.url}/api/recordings/nope/timeline", timeout=5).status_code == 404
