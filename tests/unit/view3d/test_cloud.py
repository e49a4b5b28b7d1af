"""Point clouds: read from PointCloud2's layout, thinned on a voxel grid to the bound with their extent
kept, packed into the binary frame and read back."""

import struct

import numpy as np
import pytest

from rover_web.view3d import cloud

FIELDS = [("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 8, 7, 1), ("intensity", 12, 7, 1)]


def packed(points, step=16, big=False):
    order = ">" if big else "<"
    return b"".join(struct.pack(order + "4f", *p) + b"\0" * (step - 16) for p in points)


def test_read_keeps_xyz_and_intensity_and_drops_nan():
    pts = [(1, 2, 3, 10), (float("nan"), 0, 0, 1), (4, 5, 6, 20)]
    c = cloud.read("lidar", 1.5, 1, 3, FIELDS, 16, 48, False, packed(pts))
    assert c.xyz.tolist() == [[1, 2, 3], [4, 5, 6]]
    assert c.intensity.tolist() == [10, 20]
    assert c.source_points == 3 and c.frame_id == "lidar"


def test_read_big_endian_padded_rows_and_an_organised_cloud():
    pts = [(i, -i, 0.5, i) for i in range(6)]
    rows = b"".join(packed(pts[r * 3:(r + 1) * 3], step=20, big=True) + b"\xff" * 4 for r in range(2))
    c = cloud.read("cam", 0.0, 2, 3, FIELDS, 20, 64, True, rows)
    assert c.xyz[:, 0].tolist() == [0, 1, 2, 3, 4, 5]
    assert c.xyz[:, 1].tolist() == [0, -1, -2, -3, -4, -5]


@pytest.mark.parametrize("fields, step, row, data, reason", [
    ([("x", 0, 7, 1), ("y", 4, 7, 1)], 16, 16, b"\0" * 16, "no_xyz"),
    (FIELDS, 16, 8, b"\0" * 16, "bad_layout"),
    (FIELDS, 16, 16, b"\0" * 8, "bad_layout"),
    ([("x", 0, 7, 1), ("y", 4, 7, 1), ("z", 14, 7, 1)], 16, 16, b"\0" * 16, "bad_field"),
    ([("x", 0, 9, 1), ("y", 4, 7, 1), ("z", 8, 7, 1)], 16, 16, b"\0" * 16, "bad_field"),
])
def test_bad_layouts_are_refused_with_a_reason(fields, step, row, data, reason):
    with pytest.raises(cloud.BadCloud, match=reason):
        cloud.read("f", 0.0, 1, 1, fields, step, row, False, data)


def test_too_many_points_is_refused_before_reading():
    with pytest.raises(cloud.BadCloud, match="too_large"):
        cloud.read("f", 0.0, 10_000, 10_000, FIELDS, 16, 160_000, False, b"")


@pytest.mark.parametrize("shape", ["volume", "surface", "line"])
def test_thinning_keeps_the_bound_and_the_extent(shape):
    rng = np.random.default_rng(7)
    n = 100_000
    if shape == "volume":
        xyz = rng.uniform(-10, 10, (n, 3))
    elif shape == "surface":  # a cylinder wall, as a spinning lidar sees a room
        a = rng.uniform(0, 2 * np.pi, n)
        xyz = np.stack([8 * np.cos(a), 8 * np.sin(a), rng.uniform(0, 3, n)], axis=1)
    else:
        xyz = np.stack([np.linspace(0, 50, n), np.zeros(n), np.zeros(n)], axis=1)
    xyz = xyz.astype(np.float32)
    thinned, _, voxel = cloud.voxel_thin(xyz, 20_000)
    assert 0 < len(thinned) <= 20_000
    assert len(thinned) >= 5_000, "thinned far more than the bound needs"
    # every kept point is an original one, and the box is kept to within one voxel on every side
    assert np.abs(xyz.min(axis=0) - thinned.min(axis=0)).max() <= voxel
    assert np.abs(xyz.max(axis=0) - thinned.max(axis=0)).max() <= voxel
    assert voxel > 0


def test_a_small_cloud_is_not_thinned():
    xyz = np.arange(30, dtype=np.float32).reshape(10, 3)
    thinned, intensity, voxel = cloud.voxel_thin(xyz, 20_000, np.ones(10, np.float32))
    assert thinned is xyz and voxel == 0.0 and len(intensity) == 10


def test_the_frame_round_trips_and_is_aligned():
    xyz = np.array([[1, 2, 3], [4, 5, 6]], np.float32)
    frame = cloud.encode({"seq": 5, "frame_id": "lidar"}, xyz, np.array([7, 8], np.float32))
    (length,) = struct.unpack_from("<I", frame)
    assert (4 + length) % 4 == 0
    assert len(frame) == 4 + length + 2 * 12 + 2 * 4
    header, back, intensity = cloud.decode(frame)
    assert header["count"] == 2 and header["intensity"] is True and header["seq"] == 5
    assert back.tolist() == xyz.tolist() and intensity.tolist() == [7, 8]
    header, _, intensity = cloud.decode(cloud.encode({}, xyz, None))
    assert intensity is None and header["intensity"] is False
