"""The simulated robot meets the floorplan's walls: it stops or slides, and a goal behind a wall is given up."""

import math

import numpy as np
import pytest

from rover_web.livemap.geometry import MapGeometry
from rover_web.sim.rover import DiffDrive, default_start, first_map
from rover_web.sim.walls import StallWatch, Walls, grow, occupied_cells


def test_occupied_cells_follow_map_server_thresholds_and_negate():
    image = np.array([[0, 100, 205, 254]], dtype=np.uint8)
    assert occupied_cells(image, False, 0.65).tolist() == [[True, False, False, False]]  # 100 is p = 0.61
    assert occupied_cells(image, True, 0.65).tolist() == [[False, False, True, True]]


def test_grow_makes_a_disc():
    cells = np.zeros((7, 7), dtype=bool)
    cells[3, 3] = True
    grown = grow(cells, 2)
    assert grown.sum() == 13  # the cells within 2 of the centre
    assert grown[3, 1] and grown[1, 3] and not grown[1, 1]


def drive(drive, linear, seconds, angular=0.0, dt=0.02):
    t = 0.0
    while t < seconds:
        drive.command(linear, angular, t)
        drive.step(dt, t)
        t += dt


def test_the_rover_stops_at_a_basement_wall_and_slides_along_it():
    walls = Walls.of_map(first_map())
    x, y, _ = default_start()  # the Dock, in the corridor; a room's wall 1.5 m north of it
    north = DiffDrive(x, y, math.pi / 2)
    north.walls = walls
    drive(north, 1.0, 3.0)
    assert 11.6 < north.y < 11.8 and north.x == x  # stopped a robot's radius short of the wall at 12.0

    slanted = DiffDrive(27.0, y, 1.2)  # mostly north, a little east, where the wall runs on for 7 m
    slanted.walls = walls
    drive(slanted, 1.0, 3.0)
    assert 11.6 < slanted.y < 11.8 and slanted.x > 27.0 + 1.0  # slid east along the wall


def test_a_robot_placed_in_a_wall_drives_out_and_off_the_map_nothing_blocks():
    walls = Walls(MapGeometry(10, 10, 1.0), np.ones((10, 10), dtype=bool), radius_m=0.0)
    assert walls.move(5.5, 5.5, 6.5, 5.5) == (6.5, 5.5)  # already inside: free to move
    assert walls.move(-3.0, 5.5, -0.5, 5.5) == (-0.5, 5.5)  # off the map: open space
    assert walls.move(-0.5, 5.5, 0.5, 5.5) == (-0.5, 5.5)  # but not into the wall
    assert walls.move(-2.0, 5.5, 0.5, 2.0) == pytest.approx((-0.5, 2.0))  # slides along its edge


def test_a_long_step_does_not_jump_a_thin_wall():
    cells = np.zeros((10, 10), dtype=bool)
    cells[:, 5] = True  # one cell thick, at x in [5, 6)
    walls = Walls(MapGeometry(10, 10, 1.0), cells, radius_m=0.0)
    x, y = walls.move(1.5, 5.5, 8.5, 5.5)
    assert y == 5.5 and 4.0 <= x < 5.0


def test_the_stall_watch_fires_after_pushing_without_headway_and_not_while_moving():
    watch = StallWatch(after_s=5.0, move_m=0.1)
    assert not any(watch.stalled(0.03 * i, 0.0, float(i), pushing=True) for i in range(20))  # 0.15 m per 5 s
    watch = StallWatch(after_s=5.0, move_m=0.1)
    assert [watch.stalled(0.0, 0.0, float(t), pushing=True) for t in range(7)] == [False] * 5 + [True, False]
    assert not watch.stalled(0.0, 0.0, 100.0, pushing=False)
