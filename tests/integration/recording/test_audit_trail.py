"""The audit trail inside a recording: sign-ins, waypoint and geofence edits, the e-stop, each with
who did it, on /rover_web/audit as JSON in std_msgs/msg/String, read by mcap-ros2-support and rosbags."""

from __future__ import annotations

from rover_web.recording import RecordingService
from tests.support.auth import sign_in

from .helpers import audit_records, read_mcap_ros2, read_rosbags

SQUARE = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"kind": "keep_in"},
          "geometry": {"type": "Polygon", "coordinates": [[[-82.46, 27.37], [-82.44, 27.37], [-82.44, 27.38],
                                                           [-82.46, 27.38], [-82.46, 27.37]]]}}]}


def test_operator_actions_are_in_the_file_with_who_did_them(signed_app):
    folder = signed_app.extensions["rover_web"].feature(RecordingService).folder
    client = signed_app.test_client()
    assert sign_in(client, "operator").status_code == 303
    started = client.post("/api/recordings", json={"topics": "all", "name": "audit"})
    assert started.status_code == 201, started.json
    admin = signed_app.test_client()
    assert sign_in(admin, "admin").status_code == 303
    refused = signed_app.test_client()
    assert sign_in(refused, "admin", "wrong password").status_code == 401
    assert client.post("/api/waypoints", json={"lng": -82.45, "lat": 27.375, "label": "dock"}).status_code == 201
    assert admin.put("/api/geofence", json=SQUARE).status_code == 200
    assert client.post("/api/estop", json={"engaged": True}).status_code == 200
    assert client.post("/api/estop", json={"engaged": False}).status_code == 200
    assert client.post("/logout", json={}).status_code == 200
    assert admin.post(f"/api/recordings/{started.json['id']}/stop", json={}).json["state"] == "stopped"

    path = folder / f"{started.json['id']}.mcap"
    for read in (read_mcap_ros2, read_rosbags):
        records = audit_records(read(path)["/rover_web/audit"])
        actions = [(r["action"], r["by"]) for r in records]
        for expected in [("recording.start", "operator"), ("auth.sign_in", "admin"), ("auth.sign_in_refused", "admin"),
                         ("waypoints.add_waypoint", "operator"), ("geofence.sent", "admin"),
                         ("estop.engage", "operator"), ("estop.release", "operator"), ("auth.sign_out", "operator"),
                         ("recording.stop", "admin")]:
            assert expected in actions, (read.__name__, expected, actions)
        assert actions.index(("estop.engage", "operator")) < actions.index(("estop.release", "operator"))
        stamps = [(r["timestamp"]["sec"], r["timestamp"]["nsec"]) for r in records]
        assert stamps == sorted(stamps)
