"""The replay view's data routes over a recording with known content at known times
(tests/support/mcap_files.py): the timeline's tracks, plots' fields and series, the diagnostics
board at a time, the camera frame at a time; bad questions are clear 4xx."""

from __future__ import annotations

import io

import pytest
import requests
from PIL import Image

from tests.support.mcap_files import BLUE, RED, T0, pose_x, upload, write_run


@pytest.fixture
def uploaded(live_server, tmp_path):
    answer = upload(live_server, write_run(tmp_path / "run.mcap"), name="known run")
    assert answer.status_code == 201, answer.text
    return live_server, answer.json()["id"]


def get(server, recording_id: str, what: str, **params):
    return requests.get(f"{server.url}/api/recordings/{recording_id}/{what}", params=params, timeout=30)


def test_the_timeline_has_every_track_the_logs_and_the_audit_in_time_order(uploaded):
    server, recording_id = uploaded
    timeline = get(server, recording_id, "timeline").json()
    assert (timeline["start"], timeline["end"], timeline["complete"]) == (T0, T0 + 9.95, True)
    assert timeline["topics"]["/camera/image_raw"] == {"type": "sensor_msgs/msg/Image", "count": 20,
                                                       "decodable": True}
    poses = timeline["series"]["pose"]["/amcl_pose"]
    assert len(poses) == 100 and poses[0]["frame_id"] == "map"
    assert all(p["x"] == pytest.approx(pose_x(p["t"] - T0)) and p["y"] == 2.0 and p["yaw"] == pytest.approx(0.5)
               for p in poses)
    assert [round(p["x"], 2) for p in timeline["series"]["odom"]["/odom"][:3]] == [0.0, 0.05, 0.1]
    assert len(timeline["series"]["fix"]["/fix"]) == 50 and timeline["thinned"] == {}
    assert [(line["t"], line["level"], line["msg"]) for line in timeline["logs"]] == [(T0 + 3, "WARN",
                                                                                        "thruster two hot")]
    assert [(r["t"], r["action"], r["by"]) for r in timeline["audit"]] == [(T0 + 6, "estop.engage", "carol")]


def test_plots_list_the_numeric_fields_and_read_them_over_time(uploaded):
    server, recording_id = uploaded
    fields = get(server, recording_id, "fields", topic="/odom").json()
    assert fields["type"] == "nav_msgs/msg/Odometry"
    assert {"pose.pose.position.x", "twist.twist.angular.z", "pose.covariance[0]"} <= set(fields["fields"])
    series = requests.get(f"{server.url}/api/recordings/{recording_id}/series", timeout=30, params=[
        ("topic", "/odom"), ("field", "pose.pose.position.x"), ("field", "twist.twist.angular.z")]).json()
    assert series["count"] == series["decoded"] == 200 and series["skipped_nonfinite"] == 1
    assert series["t"][0] == T0 and series["t"] == sorted(series["t"])
    assert series["v"]["pose.pose.position.x"] == pytest.approx([t - T0 for t in series["t"]])
    angular = series["v"]["twist.twist.angular.z"]
    assert angular[80] is None and angular[79] == 0.1  # NaN at s = 4 is a gap, not a number
    refusals = [(get(server, recording_id, "fields", topic="/camera/image_raw"), 422, "not_plottable"),
                (get(server, recording_id, "fields", topic="/nowhere"), 404, "unknown_topic"),
                (get(server, recording_id, "fields"), 400, "missing_field"),
                (get(server, recording_id, "series", topic="/odom", field="pose..x"), 400, "bad_field"),
                (get(server, recording_id, "series", topic="/odom"), 400, "bad_field")]
    assert [(a.status_code, a.json()["error"]) for a, *_ in refusals] == [(s, c) for _, s, c in refusals]


def test_the_diagnostics_board_is_the_one_the_live_page_showed_at_that_time(uploaded):
    server, recording_id = uploaded

    def board(s: float) -> dict:
        answer = get(server, recording_id, "diagnostics", t=T0 + s).json()
        return {st["name"]: (st["level_name"], st["message"], st["age_s"], st["stale"]) for st in answer["statuses"]}

    assert board(-1) == {}
    assert board(0.5) == {"motor": ("OK", "ok", 0.5, False), "battery": ("WARN", "low", 0.5, False)}
    assert board(5.5) == {"motor": ("ERROR", "overheat", 0.5, False), "battery": ("WARN", "low", 0.5, False),
                          "gps": ("OK", "fix", 3.5, False)}
    assert board(8.5)["gps"] == ("OK", "fix", 6.5, True)  # heard once at s = 2: stale after 5 s, as live
    answer = get(server, recording_id, "diagnostics", t=T0 + 5.5).json()
    assert [(h["hardware_id"], h["level_name"]) for h in answer["hardware"]] == \
           [("drive", "ERROR"), ("power", "WARN"), ("gnss", "OK")]
    assert [v for s in answer["statuses"] if s["name"] == "motor" for v in s["values"].items()] == [("temp", "45")]
    bad = get(server, recording_id, "diagnostics", t="soon")
    assert (bad.status_code, bad.json()["error"]) == (400, "bad_time")


def test_the_camera_frame_at_a_time_is_the_last_one_before_it(uploaded):
    server, recording_id = uploaded

    def frame(s: float, **params):
        return get(server, recording_id, "frame", topic="/camera/image_raw", t=T0 + s, **params)

    for s, logged, colour in ((0.0, 0.0, RED), (1.2, 1.0, RED), (1.6, 1.5, BLUE), (9.9, 9.5, BLUE)):
        answer = frame(s)
        assert answer.status_code == 200 and answer.headers["Content-Type"] == "image/jpeg"
        assert float(answer.headers["X-Frame-Time"]) == pytest.approx(T0 + logged)
        picture = Image.open(io.BytesIO(answer.content)).convert("RGB")
        assert picture.size == (64, 48)
        assert all(abs(a - b) < 8 for a, b in zip(picture.getpixel((32, 24)), colour, strict=True)), (s, colour)
    assert frame(-0.5).status_code == 204  # before the first frame: nothing yet
    assert Image.open(io.BytesIO(frame(2.0, width=32).content)).size == (32, 24)
    refusals = [(get(server, recording_id, "frame", topic="/odom", t=T0), 422, "not_an_image"),
                (frame(1.0, width=5), 400, "bad_width"), (frame(1.0, quality=0), 400, "bad_quality"),
                (get(server, recording_id, "frame", topic="/camera/image_raw", t="nan"), 400, "bad_time")]
    assert [(a.status_code, a.json()["error"]) for a, *_ in refusals] == [(s, c) for _, s, c in refusals]
    assert get(server, "nope", "frame", topic="/camera/image_raw", t=T0).status_code == 404
