"""The scan's thinning keeps the extreme (nearest) points; costmaps shrink keeping the highest cost."""

import math

import numpy as np
import pytest

from rover_web.overlays import costmap, scan


def make_scan(ranges, angle_min=-math.pi, range_min=0.1, range_max=30.0):
    ranges = np.asarray(ranges, dtype=np.float32)
    return scan.Scan("laser", 1.0, angle_min, 2 * math.pi / len(ranges) if len(ranges) else 0.01,
                     range_min, range_max, ranges)


def test_thinning_keeps_the_nearest_return_of_every_bin():
    rng = np.random.default_rng(7)
    ranges = rng.uniform(2.0, 10.0, 1080).astype(np.float32)
    ranges[[13, 400, 401, 1079]] = [0.5, 0.3, 0.35, 0.2]   # thin obstacles: single beams
    angles, kept, invalid = scan.thin(make_scan(ranges), 360)
    assert invalid == 0 and len(kept) == 360
    # Each kept range is the minimum of its bin of three beams.
    assert np.allclose(kept, ranges.reshape(360, 3).min(axis=1))
    for beam in (13, 400, 1079):
        assert ranges[beam] in kept
    # A naive decimation (every third beam) would have lost them.
    assert not {0.5, 0.3, 0.2} & set(ranges[::3].round(3).tolist())
    # Angles are the kept beams' own.
    i = int(np.argmin(kept))
    assert angles[i] == pytest.approx(-math.pi + 1079 * 2 * math.pi / 1080)


def test_a_bin_keeps_its_farthest_return_too_when_it_stands_out_a_doorway_or_a_long_beam():
    ranges = np.full(1080, 2.0, dtype=np.float32)
    ranges[0::3] = 1.9                      # each bin of three: a nearest at 1.9 m
    ranges[301] = 25.0                      # one 25 m beam among walls (bin 100)
    ranges[600:603] = [5.0, 4.8, 5.2]       # a doorway filling bin 200: its nearest 4.8, farthest 5.2
    ranges[900] = float("nan")              # bin 300: its valid returns 2.0, 2.0: nothing stands out
    t = scan.thin_both(make_scan(ranges), 360)
    assert len(t.ranges) == 360 and t.invalid == 1
    assert t.ranges[100] == pytest.approx(1.9) and t.ranges[200] == pytest.approx(4.8)
    # Only the bins whose farthest is >= FAR_MIN_GAP_M beyond their nearest: the long beam and the doorway.
    assert t.far_ranges.tolist() == pytest.approx([25.0, 5.2])
    step = 2 * math.pi / 1080
    assert t.far_angles == pytest.approx([-math.pi + 301 * step, -math.pi + 602 * step])
    # The nearest-only thinning drops the 25 m beam: what the far return is for.
    assert 25.0 not in scan.thin(make_scan(ranges), 360)[1]
    # A scan no denser than its bins keeps every beam once, as nearest.
    few = scan.thin_both(make_scan([1.0, 9.0, 2.0]), 360)
    assert few.ranges.tolist() == [1.0, 9.0, 2.0] and few.far_ranges.size == 0


def test_invalid_returns_are_dropped_and_counted():
    ranges = [1.0, float("nan"), float("inf"), -float("inf"), 0.05, 31.0, 2.0, 3.0]
    angles, kept, invalid = scan.thin(make_scan(ranges), 360)
    assert invalid == 5 and kept.tolist() == [1.0, 2.0, 3.0]
    assert scan.thin(make_scan([float("nan")] * 10), 4)[2] == 10


def test_a_bin_of_only_invalid_beams_keeps_nothing_and_other_bins_keep_their_own():
    ranges = [float("nan")] * 4 + [5.0, 4.0, 6.0, 7.0]
    _, kept, _ = scan.thin(make_scan(ranges), 2)
    assert kept.tolist() == [4.0]


def test_bad_scans_are_refused():
    with pytest.raises(scan.BadScan, match="empty"):
        scan.check(make_scan([]))
    with pytest.raises(scan.BadScan, match="bad_header"):
        scan.check(make_scan([1.0], angle_min=float("nan")))


def test_points_go_to_the_map_frame_with_the_robot_and_laser_pose():
    # Robot at (1, 2) facing +y; laser 0.5 m ahead of its centre, turned to face the robot's left.
    points = scan.to_map(np.array([0.0]), np.array([2.0]), (1.0, 2.0, math.pi / 2), (0.5, 0.0, math.pi / 2))
    assert points[0] == pytest.approx([1.0 - 2.0, 2.5])


def test_a_costmap_too_big_shrinks_keeping_each_blocks_highest_cost():
    cells = np.zeros((1000, 1000), dtype=np.int8)
    cells[500, 501] = 100            # one lethal cell
    cells[0:4, 0:4] = -1             # an unknown block
    out, factor = costmap.shrink(cells.ravel(), 1000, 1000, 400)
    assert factor == 3 and out.shape == (334, 334)
    assert out[500 // 3, 501 // 3] == 100 and out.sum(dtype=np.int64) - 255 * (out == 255).sum() == 100
    assert out[0, 0] == costmap.UNKNOWN


def test_costmap_checks():
    def grid(w, h, n):
        return costmap.Grid("map", 0.0, w, h, 0.05, (0.0, 0.0, 0.0), np.zeros(n, dtype=np.int8))
    costmap.check(grid(10, 10, 100), 1000)
    for bad, reason in ((grid(10, 10, 99), "size_mismatch"), (grid(0, 0, 0), "empty"),
                        (grid(100, 100, 10000), "too_large")):
        with pytest.raises(costmap.BadGrid, match=reason):
            costmap.check(bad, 1000)
