"""The simulator's planner: paths around the basement's walls, Nav2's error codes when there is none,
and the plan driven corner to corner."""

import math

import numpy as np
import pytest

from rover_web.livemap.geometry import MapGeometry
from rover_web.sim.nav2_server import PlanDrive
from rover_web.sim.planner import (
    GOAL_OCCUPIED,
    GOAL_OUTSIDE_MAP,
    NO_VALID_PATH,
    GridPlanner,
    PlanError,
    path_length,
)
from rover_web.sim.rover import DiffDrive, GoalFollower, default_start, first_map
from rover_web.sim.walls import Walls


@pytest.fixture(scope="module")
def basement():
    return Walls.of_map(first_map())


def segment_clear(walls: Walls, a, b) -> bool:
    """Every 1 cm along the segment is free for the robot (the walls grown by its radius)."""
    n = max(1, math.ceil(math.hypot(b[0] - a[0], b[1] - a[1]) / 0.01))
    return not any(walls.is_blocked(a[0] + (b[0] - a[0]) * i / n, a[1] + (b[1] - a[1]) * i / n)
                   for i in range(n + 1))


def room(width=60, height=40, wall_col=None, door=None):
    """A 0.1 m grid with a border wall and optionally a wall across at `wall_col` with a door of rows."""
    occupied = np.zeros((height, width), dtype=bool)
    occupied[0, :] = occupied[-1, :] = occupied[:, 0] = occupied[:, -1] = True
    if wall_col is not None:
        occupied[:, wall_col] = True
        if door:
            occupied[door[0]:door[1], wall_col] = False
    return Walls(MapGeometry(width, height, 0.1), occupied, radius_m=0.2)


def test_an_open_room_is_one_straight_line():
    walls = room()
    path = GridPlanner(walls).plan((1.0, 1.0), (5.0, 3.0))
    assert path == [(1.0, 1.0), (5.0, 3.0)]


def test_a_wall_with_a_door_is_passed_through_the_door():
    # wall at x = 3.0..3.1 m; door in image rows 5..15, i.e. y from 2.5 to 3.5 m (rows count from the top)
    walls = room(wall_col=30, door=(5, 15))
    path = GridPlanner(walls).plan((1.0, 1.0), (5.0, 1.0))
    assert path[0] == (1.0, 1.0) and path[-1] == (5.0, 1.0)
    crossing = [(a, b) for a, b in zip(path, path[1:], strict=False) if (a[0] - 3.05) * (b[0] - 3.05) <= 0]
    assert len(crossing) == 1
    (ax, ay), (bx, by) = crossing[0]
    y_at_wall = ay + (by - ay) * (3.05 - ax) / (bx - ax)
    assert 2.7 <= y_at_wall <= 3.3  # through the door, clear of its posts by the robot's radius
    assert all(segment_clear(walls, a, b) for a, b in zip(path, path[1:], strict=False))
    assert path_length(path) > 2 * math.hypot(2.0, 1.6)  # up to the door (y >= 2.7) and down again, not 4 m


def test_a_wall_without_a_door_has_no_valid_path():
    walls = room(wall_col=30)
    with pytest.raises(PlanError) as info:
        GridPlanner(walls).plan((1.0, 1.0), (5.0, 1.0))
    assert info.value.code == NO_VALID_PATH


def test_goals_in_a_wall_or_off_the_map_are_refused_with_nav2s_codes():
    walls = room(wall_col=30)
    planner = GridPlanner(walls)
    with pytest.raises(PlanError) as info:
        planner.plan((1.0, 1.0), (3.05, 2.0))
    assert info.value.code == GOAL_OCCUPIED
    with pytest.raises(PlanError) as info:
        planner.plan((1.0, 1.0), (1.0, 0.1))  # free in the image, but within the robot's radius of the wall
    assert info.value.code == GOAL_OCCUPIED
    with pytest.raises(PlanError) as info:
        planner.plan((1.0, 1.0), (9.0, 1.0))
    assert info.value.code == GOAL_OUTSIDE_MAP


def test_no_walls_means_open_ground():
    assert GridPlanner(None).plan((0.0, 0.0), (100.0, -3.0)) == [(0.0, 0.0), (100.0, -3.0)]


@pytest.mark.parametrize("name", ["Lab B12", "Workshop", "Boiler Room", "Stairs", "Elevator"])
def test_every_basement_waypoint_is_reached_around_the_walls(basement, name):
    waypoint = next(w for w in first_map().waypoints if w.name == name)
    start = default_start()[:2]
    path = GridPlanner(basement).plan(start, (waypoint.x, waypoint.y))
    assert path[0] == start and path[-1] == (waypoint.x, waypoint.y)
    assert all(segment_clear(basement, a, b) for a, b in zip(path, path[1:], strict=False))
    assert path_length(path) >= math.hypot(waypoint.x - start[0], waypoint.y - start[1]) - 1e-9


def test_a_plan_is_driven_to_its_end_through_its_corners_without_touching_a_wall():
    walls = room(wall_col=30, door=(5, 15))
    path = GridPlanner(walls).plan((1.0, 1.0), (5.0, 1.0))
    drive = DiffDrive(1.0, 1.0, 0.0)
    drive.walls = walls
    plan = PlanDrive(path, math.pi / 2, GoalFollower(max_linear_mps=0.5))
    t, dt = 0.0, 0.02
    start_remaining = plan.distance_remaining(drive.x, drive.y)
    assert start_remaining == pytest.approx(path_length(path))
    while not plan.done and t < 60:
        drive.command(*plan.command(drive.x, drive.y, drive.yaw), t)
        before = (drive.x, drive.y)
        drive.step(dt, t)
        # never slid along a wall: the robot went where it was told (walls.move would have cut it short)
        assert not walls.is_blocked(drive.x, drive.y), before
        t += dt
    assert plan.done
    assert math.hypot(drive.x - 5.0, drive.y - 1.0) < 0.06
    assert abs(math.atan2(math.sin(drive.yaw - math.pi / 2), math.cos(drive.yaw - math.pi / 2))) < 0.06
    assert plan.distance_remaining(drive.x, drive.y) == 0.0
