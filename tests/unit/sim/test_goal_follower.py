"""The simulator's goal follower driving the simulator's kinematics: it arrives, turns, and stops."""

import math

import pytest

from rover_web.sim.rover import DiffDrive, GoalFollower


def drive_to(follower, drive, seconds=60.0, dt=0.02):
    """Run the follower on the kinematics the way RoverSim's tick does; return the time taken."""
    t = 0.0
    while follower.active and t < seconds:
        linear, angular = follower.command(drive.x, drive.y, drive.yaw)
        drive.command(linear, angular, t)
        drive.step(dt, t)
        t += dt
    return t


@pytest.mark.parametrize("start, goal", [
    ((0.0, 0.0, 0.0), (4.0, 0.0, 0.0)),                 # straight ahead
    ((0.0, 0.0, 0.0), (-3.0, 2.0, math.pi / 2)),       # behind and to the left
    ((2.0, 10.5, 0.0), (23.0, 4.0, -math.pi)),         # across the basement
    ((1.0, 1.0, 2.0), (1.02, 1.0, 1.0)),               # already there: only turn
    ((0.0, 0.0, 0.0), (0.0, -0.5, 0.0)),               # a short hop sideways
])
def test_reaches_the_goal_position_and_heading_then_stops(start, goal):
    drive = DiffDrive(*start, cmd_timeout_s=0.5)
    follower = GoalFollower(max_linear_mps=0.5, max_angular_rps=1.0)
    assert follower.set_goal(*goal)
    elapsed = drive_to(follower, drive)
    assert not follower.active and follower.reached == 1, f"still driving after {elapsed:.1f} s"
    assert math.hypot(drive.x - goal[0], drive.y - goal[1]) <= follower.position_tolerance_m + 0.02
    assert abs(math.atan2(math.sin(drive.yaw - goal[2]), math.cos(drive.yaw - goal[2]))) <= 0.06
    distance = math.hypot(goal[0] - start[0], goal[1] - start[1])
    assert elapsed < distance / 0.5 * 1.6 + 8.0   # roughly straight, not a wander
    assert follower.command(drive.x, drive.y, drive.yaw) == (0.0, 0.0)
    drive.command(0.0, 0.0, elapsed)
    x, y = drive.x, drive.y
    drive.step(1.0, elapsed + 1.0)
    assert (drive.x, drive.y) == (x, y)


def test_speeds_stay_within_the_limits_and_it_never_reverses():
    drive = DiffDrive(0.0, 0.0, 0.0)
    follower = GoalFollower(max_linear_mps=0.3, max_angular_rps=0.8)
    follower.set_goal(-5.0, 5.0, 0.0)
    for i in range(3000):
        linear, angular = follower.command(drive.x, drive.y, drive.yaw)
        assert 0.0 <= linear <= 0.3 and abs(angular) <= 0.8
        drive.command(linear, angular, i * 0.02)
        drive.step(0.02, i * 0.02)
        if not follower.active:
            break
    assert follower.reached == 1


def test_facing_away_it_turns_before_it_drives():
    follower = GoalFollower()
    follower.set_goal(-5.0, 0.0, 0.0)
    linear, angular = follower.command(0.0, 0.0, 0.0)
    assert linear == 0.0 and abs(angular) == follower.max_angular_rps


def test_cancel_and_bad_goals():
    follower = GoalFollower()
    assert follower.cancel() is False
    assert follower.set_goal(float("nan"), 0.0, 0.0) is False and not follower.active
    assert follower.set_goal(1.0, 0.0, float("inf")) is False
    follower.set_goal(3.0, 0.0, 0.0)
    assert follower.command(0.0, 0.0, 0.0)[0] > 0
    assert follower.cancel() is True and not follower.active
    assert follower.command(0.0, 0.0, 0.0) == (0.0, 0.0) and follower.reached == 0
