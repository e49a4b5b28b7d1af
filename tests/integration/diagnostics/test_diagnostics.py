"""Diagnostics against a real publisher: GET /api/diagnostics and the `diagnostics` channel carry the latest
status per name, /diagnostics_agg too, the worst level per hardware id, and a silent status turns stale."""

import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.ros

ARRAY = "diagnostic_msgs/msg/DiagnosticArray"


def status(name, level, hardware_id, message, **values):
    return {"name": name, "level": level, "hardware_id": hardware_id, "message": message,
            "values": [{"key": k, "value": v} for k, v in values.items()]}


def statuses(server):
    return {s["name"]: s for s in requests.get(server.url + "/api/diagnostics", timeout=5).json()["statuses"]}


def test_latest_status_per_name_then_stale(live_server_factory, ros_peer, sse_client):
    server = live_server_factory(ROVER_WEB_DIAGNOSTICS_STALE_S=1.0)
    stream = sse_client(server.url + "/api/events?channels=diagnostics")
    peer = ros_peer("diag_peer")
    peer.advertise("/diagnostics", ARRAY)
    peer.advertise("/diagnostics_agg", ARRAY)
    peer.wait_match("/diagnostics")
    peer.wait_match("/diagnostics_agg")
    peer.publish("/diagnostics", {"status": [status("battery", 1, "bms", "low", voltage="22.9"),
                                             status("left motor", 0, "motors", "ok", temp="40")]})
    peer.publish("/diagnostics", {"status": [status("right motor", 2, "motors", "stalled")]})
    peer.publish("/diagnostics_agg", {"status": [status("/Sensors/GPS", 0, "gps", "fixed")]})
    got = wait_until(lambda: len(s := statuses(server)) == 4 and s, 15, "four statuses")
    assert got["battery"] == {**got["battery"], "hardware_id": "bms", "level": 1, "level_name": "WARN",
                              "message": "low", "values": {"voltage": "22.9"}, "stale": False,
                              "source": "/diagnostics"}
    assert got["/Sensors/GPS"]["source"] == "/diagnostics_agg"
    assert 0 <= got["battery"]["age_s"] < 1.0
    hardware = requests.get(server.url + "/api/diagnostics", timeout=5).json()["hardware"]
    assert [(h["hardware_id"], h["level_name"]) for h in hardware] == [("motors", "ERROR"), ("bms", "WARN"),
                                                                       ("gps", "OK")]
    # The channel carries the same, and then says stale when nothing refreshes them.
    stream.wait_for("diagnostics", lambda d: len(d["statuses"]) == 4, timeout=5)
    peer.publish("/diagnostics", {"status": [status("battery", 0, "bms", "charged")]})
    stream.wait_for("diagnostics", lambda d: any(s["name"] == "battery" and s["level"] == 0 for s in d["statuses"]),
                    timeout=5)
    event = stream.wait_for("diagnostics", lambda d: all(s["stale"] for s in d["statuses"]), timeout=10)
    assert {h["level_name"] for h in event["json"]["hardware"]} == {"STALE"}
    assert all(s["stale"] for s in statuses(server).values())
    # The page shows them too.
    page = requests.get(server.url + "/diagnostics", timeout=5).text
    assert "right motor" in page and "stalled" in page and "STALE" in page
