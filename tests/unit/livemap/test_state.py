"""The campus rover's LiveMap map_state, the robot track, path thinning and channel payloads."""

import math

import numpy as np
import pytest

from rover_web.livemap.geometry import MapGeometry
from rover_web.livemap.map_files import MapDefinition, Waypoint
from rover_web.livemap.occupancy import FREE_GREY, OCCUPIED_GREY, UNKNOWN_GREY, grid_to_image, image_to_png
from rover_web.livemap.state import (
    LiveMap,
    Pose2D,
    RobotTrack,
    UnknownMap,
    downsample,
    goal_payload,
    plan_payload,
    pose_payload,
)

HALL_GEOMETRY = MapGeometry(800, 480, 0.05, -2.0, -1.5, 0.0)


def definition(name="Hall", geometry=HALL_GEOMETRY, waypoints=()):
    files = {"path": "hall/", "png": {"file_name": "hall.png", "cm_per_pixel": geometry.cm_per_pixel,
                                      "pixel_width": geometry.width_px, "pixel_height": geometry.height_px}}
    yaml = {"resolution": geometry.resolution_m, "origin": [geometry.origin_x, geometry.origin_y, geometry.origin_yaw]}
    return MapDefinition(name, geometry, files, yaml, tuple(waypoints))


HALL = definition(waypoints=[Waypoint("Dock", 0.0, 0.0, 0.0)])
CATALOG = {"Hall": HALL}


def test_map_state_has_the_campus_rover_shape_with_width_and_height_in_their_places():
    live = LiveMap("Hall", 2, catalog=CATALOG)
    params, scaled = live.map_state["map_parameters"], live.map_state["scaled_pixel_values"]
    assert params["map_name"] == "Hall"
    assert params["files"]["png"] == {"file_name": "hall.png", "cm_per_pixel": 5.0,
                                      "pixel_width": 800, "pixel_height": 480}
    assert params["files"]["yaml"] == {"resolution": 0.05, "origin": [-2.0, -1.5, 0.0]}
    assert params["bot_radius"] == pytest.approx(17.7)                  # cm, half of 35.4
    assert params["cm_per_pixel"] == 2.0
    assert params["waypoints"] == [{"name": "Dock", "x": 0.0, "y": 0.0, "yaw": 0.0}]
    assert params["current_pose"] == {} and params["goal_pose"] == {}
    assert scaled["cm_per_pixel"] == 2.0 and scaled["scale"] == pytest.approx(2.5)
    assert scaled["png_pixel_width"] == pytest.approx(2000.0)          # 800 px of 5 cm at 2 cm per pixel
    assert scaled["png_pixel_height"] == pytest.approx(1200.0)
    assert scaled["bot_radius"] == pytest.approx(8.85)                  # 17.7 cm at 2 cm per pixel
    assert scaled["waypoints"] == [pytest.approx({"name": "Dock", "x": 100.0, "y": 1125.0})]


def test_the_default_scale_is_the_image_s_own_and_the_diameter_is_configurable():
    live = LiveMap("Hall", catalog=CATALOG, bot_cm_diameter=50)
    scaled = live.map_state["scaled_pixel_values"]
    assert scaled["cm_per_pixel"] == 5.0 and scaled["scale"] == 1.0
    assert scaled["png_pixel_width"] == 800 and scaled["png_pixel_height"] == 480
    assert scaled["bot_radius"] == pytest.approx(5.0)


def test_poses_in_map_metres_and_display_pixels():
    live = LiveMap("Hall", 10, catalog=CATALOG)                         # half size: 400 x 240
    live.update_current_pose(Pose2D(18.0, 10.5, math.pi / 2, "map", 12.5), age_s=0.1)
    live.update_goal_pose(Pose2D(38.0, -1.5, 0.0))
    params, scaled = live.map_state["map_parameters"], live.map_state["scaled_pixel_values"]
    assert params["current_pose"] == {"x": 18.0, "y": 10.5, "yaw": math.pi / 2, "frame_id": "map",
                                      "stamp": 12.5, "age_s": 0.1, "stale": False}
    assert scaled["current_pose"] == pytest.approx({"x": 200.0, "y": 120.0, "yaw": math.pi / 2, "inside": True})
    assert scaled["goal_pose"] == pytest.approx({"x": 400.0, "y": 240.0, "yaw": 0.0, "inside": True})
    assert live.to_world(200.0, 120.0) == pytest.approx((18.0, 10.5))
    live.update_current_pose(None)
    assert live.map_state["scaled_pixel_values"]["current_pose"] == {}


@pytest.mark.parametrize("cm", [0, -1, float("nan"), float("inf"), 1e9, True])
def test_bad_scales_are_refused(cm):
    with pytest.raises(ValueError):
        LiveMap("Hall", cm, catalog=CATALOG)


def test_unknown_map():
    with pytest.raises(UnknownMap):
        LiveMap("Attic", 2, catalog=CATALOG)


def test_the_default_catalog_is_the_shipped_one():
    live = LiveMap("Science Hall Basement", 2)
    assert live.map_state["scaled_pixel_values"]["png_pixel_width"] == pytest.approx(2000.0)


def test_track_staleness_and_goal_echo():
    now = [100.0]
    track = RobotTrack(stale_after_s=2.0, clock=lambda: now[0])
    assert track.pose() == (None, None, True)
    track.set_pose(Pose2D(1.0, 2.0, 0.0))
    now[0] = 101.5
    pose, age, stale = track.pose()
    assert pose.x == 1.0 and age == pytest.approx(1.5) and not stale
    now[0] = 102.5
    assert track.pose()[2] is True
    never = RobotTrack(stale_after_s=0.0, clock=lambda: now[0])
    never.set_pose(Pose2D(1.0, 2.0, 0.0))
    now[0] = 1e6
    assert never.pose()[2] is False
    goal = Pose2D(1.0, 2.0, 0.5, "map", 3.0)
    assert track.set_goal(goal) is True
    assert track.set_goal(Pose2D(1.0, 2.0, 0.5 + 1e-15, "map", 3.0)) is False  # the same goal heard back
    assert track.set_goal(Pose2D(1.0, 2.0, 0.5, "map", 4.0)) is True


def test_downsample_keeps_the_ends_and_spreads_evenly():
    points = list(range(10001))
    kept = downsample(points, 500)
    assert len(kept) == 500 and kept[0] == 0 and kept[-1] == 10000
    gaps = np.diff(kept)
    assert gaps.min() >= 20 and gaps.max() <= 21
    assert downsample(points[:5], 500) == [0, 1, 2, 3, 4]
    assert downsample([], 10) == []


def test_payloads_carry_pixels_for_every_map():
    lab = definition("Lab", MapGeometry(480, 360, 0.025, -6.0, -4.5, 0.0))
    payload = pose_payload(Pose2D(0.0, 0.0, 3 * math.pi, "map", 7.25), [HALL, lab], age_s=0.0)
    assert payload["yaw"] == pytest.approx(math.pi, abs=1e-4)
    assert payload["pixels"]["Hall"] == {"x": 40.0, "y": 450.0, "yaw": pytest.approx(math.pi, abs=1e-4), "inside": True}
    assert payload["pixels"]["Lab"] == {"x": 240.0, "y": 180.0, "yaw": pytest.approx(math.pi, abs=1e-4), "inside": True}
    assert payload["stale"] is False and payload["stamp"] == 7.25
    goal = goal_payload(Pose2D(10.0, 10.0, 0.0), [lab])
    assert goal["pixels"]["Lab"]["inside"] is False and "stale" not in goal
    plan = plan_payload("map", [(i * 0.01, 0.0) for i in range(2000)], 100)
    assert plan["length"] == 2000 and len(plan["points"]) == 100
    assert plan["points"][0] == [0.0, 0.0] and plan["points"][-1] == [19.99, 0.0]


def test_a_far_away_pose_has_no_pixel_but_stays_valid_json():
    import json
    payload = pose_payload(Pose2D(1e308, 0.0, 0.0), [HALL])
    assert payload["pixels"]["Hall"] == {"x": None, "y": None, "yaw": 0.0, "inside": False}
    json.dumps(payload, allow_nan=False)
    live = LiveMap("Hall", catalog=CATALOG)
    live.update_current_pose(Pose2D(-1e308, 0.0, 0.0))
    json.dumps(live.map_state, allow_nan=False)


def test_occupancy_grid_image_distinguishes_free_occupied_and_unknown():
    width, height = 4, 3
    cells = np.full(width * height, -1, dtype=np.int8)
    cells[0] = 0          # grid (col 0, row 0): the origin cell, bottom-left of the image
    cells[1] = 100        # (1, 0)
    cells[width + 2] = 50  # (2, 1): uncertain
    cells[2 * width + 3] = 25  # (3, 2): top-right, free at the threshold
    image = grid_to_image(cells, width, height)
    assert image.shape == (3, 4) and image.dtype == np.uint8
    assert image[2, 0] == FREE_GREY and image[2, 1] == OCCUPIED_GREY and image[0, 3] == FREE_GREY
    assert image[0, 0] == UNKNOWN_GREY and image[1, 2] == 127
    assert len({FREE_GREY, OCCUPIED_GREY, UNKNOWN_GREY, int(image[1, 2])}) == 4
    assert image_to_png(image).startswith(b"\x89PNG")
