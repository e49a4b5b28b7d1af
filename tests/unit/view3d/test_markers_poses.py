"""3D markers kept as RViz keeps them, and every TF frame's pose in the base frame from a real TfBuffer."""

import math

import pytest

from rover_web.tf.buffer import TfBuffer
from rover_web.view3d import poses
from rover_web.view3d.markers import BadMarker, Markers3d


def marker(mid=1, kind=1, action=0, **extra):
    m = {"ns": "n", "id": mid, "type": kind, "action": action, "frame_id": "odom", "stamp": 0.0,
         "pose": [1, 2, 3, 0, 0, 0, 1], "scale": [1, 1, 1], "color": [1, 0, 0, 1], "points": [], "colors": [],
         "text": "", "mesh_resource": "", "lifetime_s": 0.0, "frame_locked": False}
    m.update(extra)
    return m


def test_add_replace_delete_deleteall_and_lifetime():
    ms = Markers3d()
    ms.apply(marker(1), 0.0)
    ms.apply(marker(1, kind=2), 0.0)
    ms.apply(marker(2, kind=9, text="hi", lifetime_s=1.0), 0.0)
    assert sorted(m["kind"] for m in ms.payload()) == ["sphere", "text"]
    assert not ms.expire(0.5) and ms.expire(1.5)
    assert [m["kind"] for m in ms.payload()] == ["sphere"]
    ms.apply(marker(1, action=2), 2.0)
    assert ms.payload() == []
    ms.apply(marker(3, kind=10, mesh_resource="package://p/m.stl"), 0.0)
    assert ms.payload()[0]["mesh"] == "package://p/m.stl"
    ms.apply(marker(0, action=3), 0.0)
    assert ms.payload() == []


@pytest.mark.parametrize("bad, reason", [
    (marker(kind=42), "unsupported_type"), (marker(action=7), "bad_action"),
    (marker(pose=[math.nan, 0, 0, 0, 0, 0, 1]), "not_finite"),
    (marker(kind=8, points=[[0, math.inf, 0]]), "not_finite"),
    (marker(kind=8, points=[[0, 0, 0]] * 20001), "too_many_points"),
])
def test_bad_markers_are_refused(bad, reason):
    with pytest.raises(BadMarker, match=reason):
        Markers3d().apply(bad, 0.0)


def test_every_frame_in_the_base_frame():
    b = TfBuffer()
    b.set_transform("map", "odom", (10, 0, 0), (0, 0, 0, 1), 0, static=True)
    b.set_transform("odom", "base_link", (1, 2, 0), (0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4)), 10**9,
                    static=False)
    b.set_transform("base_link", "arm", (0, 0, 0.15), (0, 0, 0, 1), 10**9, static=False)
    b.set_transform("island", "rock", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    names = poses.frame_names(b)
    assert names == ["arm", "base_link", "island", "map", "odom", "rock"]
    found = poses.in_base(b, "base_link", names)
    assert found["base_link"] == [0, 0, 0, 0, 0, 0, 1]
    assert found["arm"] == [0, 0, 0.15, 0, 0, 0, 1]
    # odom seen from a base turned 90° left at (1, 2): odom's origin is at (-2, 1) in base_link
    assert found["odom"][:3] == pytest.approx([-2, 1, 0], abs=1e-6)
    assert found["map"][:3] == pytest.approx([-2, 11, 0], abs=1e-6)
    assert found["island"] is None and found["rock"] is None  # another tree: TF cannot place them


def test_a_marker_keeps_where_its_frame_was_at_its_stamp_unless_stamped_0_or_frame_locked():
    asked = []

    def place(frame, stamp):
        asked.append((frame, stamp))
        if stamp < 5:
            raise BadMarker("tf_extrapolation_past")
        return {"map": [1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0]}

    kept = Markers3d()
    kept.apply(marker(1, stamp=10.0, frame_id="base_link"), 0.0, place)
    kept.apply(marker(2, stamp=0.0, frame_id="base_link"), 0.0, place)
    kept.apply(marker(3, stamp=10.0, frame_id="base_link", frame_locked=True), 0.0, place)
    with pytest.raises(BadMarker, match="tf_extrapolation_past"):
        kept.apply(marker(4, stamp=1.0, frame_id="base_link"), 0.0, place)
    by_id = {m["id"]: m for m in kept.payload()}
    assert by_id[1]["at_stamp"] == {"map": [1.0, 2.0, 0.0, 0.0, 0.0, 0.0, 1.0]}
    assert "at_stamp" not in by_id[2] and "at_stamp" not in by_id[3] and 4 not in by_id
    assert asked == [("base_link", 10.0), ("base_link", 1.0)]  # stamp 0 and frame_locked: never looked up
