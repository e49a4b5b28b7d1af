"""The TF buffer against 4x4 matrices composed with scipy's Rotation (an independent, well-kept oracle).

Chains, inverses, lookups across branches through the common ancestor, interpolation (linear
translation, slerp rotation, checked against scipy's Slerp), the latest common time, the cache
window, and tf2's refusals with how far a stamp is outside the data.
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation, Slerp

from rover_web.tf.buffer import TfBuffer, TfError, Transform

coord = st.floats(-50, 50, allow_nan=False)
vec = st.tuples(coord, coord, coord)
quat = (st.tuples(*[st.floats(-1, 1)] * 4)
        .filter(lambda q: sum(v * v for v in q) > 0.05)
        .map(lambda q: tuple(v / math.sqrt(sum(w * w for w in q)) for v in q)))
link = st.tuples(vec, quat)
S = 1_000_000_000


def matrix(t, q):
    m = np.eye(4)
    m[:3, :3] = Rotation.from_quat(q).as_matrix()  # scipy's order is x, y, z, w like ours
    m[:3, 3] = t
    return m


def as_matrix(tf: Transform):
    return matrix(tf.translation, tf.rotation)


def close(tf: Transform, m, tol=1e-7):
    np.testing.assert_allclose(as_matrix(tf), m, atol=tol * max(1.0, np.abs(m[:3, 3]).max()))


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.lists(link, min_size=1, max_size=10))
def test_a_chain_is_the_product_of_its_links(links):
    buf = TfBuffer()
    expected = np.eye(4)
    for i, (t, q) in enumerate(links):
        buf.set_transform(f"f{i}", f"f{i + 1}", t, q, 0, static=True)
        expected = expected @ matrix(t, q)
    n = len(links)
    close(buf.lookup("f0", f"f{n}"), expected)
    close(buf.lookup(f"f{n}", "f0"), np.linalg.inv(expected))
    point = np.array([1.0, -2.0, 0.5, 1.0])
    np.testing.assert_allclose(buf.lookup("f0", f"f{n}").apply(*point[:3]), (expected @ point)[:3],
                               atol=1e-6 * max(1.0, np.abs(expected).max()))


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.lists(link, min_size=1, max_size=5), st.lists(link, min_size=1, max_size=5), st.lists(link, max_size=3))
def test_two_branches_meet_at_their_common_ancestor(left, right, trunk):
    buf = TfBuffer()
    parent, top = "root", np.eye(4)
    for i, (t, q) in enumerate(trunk):
        buf.set_transform(parent, f"trunk{i}", t, q, 0, static=True)
        parent, top = f"trunk{i}", top @ matrix(t, q)
    mats = {}
    for side, links in (("a", left), ("b", right)):
        p, m = parent, np.eye(4)
        for i, (t, q) in enumerate(links):
            buf.set_transform(p, f"{side}{i}", t, q, 0, static=True)
            p, m = f"{side}{i}", m @ matrix(t, q)
        mats[side] = (p, m)
    (a, ma), (b, mb) = mats["a"], mats["b"]
    close(buf.lookup(a, b), np.linalg.inv(ma) @ mb, tol=1e-6)
    close(buf.lookup("root", b), top @ mb, tol=1e-6)


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(link, link)
def test_transform_inverse_and_compose_are_matrix_inverse_and_product(a, b):
    ta, tb = Transform(*a), Transform(*b)
    close(ta.inverse(), np.linalg.inv(matrix(*a)))
    close(ta.compose(tb), matrix(*a) @ matrix(*b))
    close(ta.compose(ta.inverse()), np.eye(4))


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(link, st.lists(vec, min_size=1, max_size=20))
def test_apply_many_is_apply_on_each_point(a, points):
    tf = Transform(*a)
    xs, ys, zs = zip(*points, strict=True)
    out = np.stack(tf.apply_many(xs, ys, zs), axis=1)
    np.testing.assert_allclose(out, [tf.apply(*p) for p in points], atol=1e-9)
    flat = np.stack(tf.apply_many(xs, ys), axis=1)
    np.testing.assert_allclose(flat, [tf.apply(x, y) for x, y, _ in points], atol=1e-9)


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(quat)
def test_yaw_is_the_heading_about_z(q):
    m = Rotation.from_quat(q).as_matrix()
    assume(math.hypot(m[0, 0], m[1, 0]) > 0.1)  # pitched near ±90°, the heading is undefined
    yaw = math.atan2(m[1, 0], m[0, 0])  # where the body's x axis points, seen from above
    assert math.cos(Transform((0, 0, 0), q).yaw - yaw) == pytest.approx(1.0, abs=1e-9)


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(link, link, st.floats(0.0, 1.0), st.integers(1, 10_000))
def test_between_two_stamps_translation_is_linear_and_rotation_is_slerp(a, b, r, gap_ms):
    buf = TfBuffer()
    t0, t1 = 100 * S, 100 * S + gap_ms * 1_000_000
    buf.set_transform("odom", "base", a[0], a[1], t0, static=False)
    buf.set_transform("odom", "base", b[0], b[1], t1, static=False)
    stamp = t0 + round(r * (t1 - t0))
    r = (stamp - t0) / (t1 - t0)
    got = buf.lookup("odom", "base", stamp)
    assert got.stamp_ns == stamp
    np.testing.assert_allclose(got.translation, np.array(a[0]) + r * (np.array(b[0]) - np.array(a[0])), atol=1e-9)
    qb = np.array(b[1]) if np.dot(a[1], b[1]) >= 0 else -np.array(b[1])  # tf2 takes the shorter arc
    oracle = Slerp([0.0, 1.0], Rotation.from_quat([a[1], qb]))([r])
    np.testing.assert_allclose(Rotation.from_quat(got.rotation).as_matrix(), oracle.as_matrix()[0], atol=1e-6)


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(link, link, link, st.floats(0.0, 1.0))
def test_a_chain_interpolates_each_dynamic_link_and_keeps_static_ones(mount, a, b, r):
    buf = TfBuffer()
    buf.set_transform("base", "laser", mount[0], mount[1], 0, static=True)
    buf.set_transform("odom", "base", a[0], a[1], 10 * S, static=False)
    buf.set_transform("odom", "base", b[0], b[1], 11 * S, static=False)
    stamp = 10 * S + round(r * S)
    base = buf.lookup("odom", "base", stamp)
    close(buf.lookup("odom", "laser", stamp), as_matrix(base) @ matrix(*mount), tol=1e-6)


def test_the_latest_common_time_is_the_oldest_newest_stamp_on_the_path():
    buf = TfBuffer()
    for s in (1, 2, 3):
        buf.set_transform("map", "odom", (s, 0, 0), (0, 0, 0, 1), s * S, static=False)
    for s in (1, 2):
        buf.set_transform("odom", "base", (0, s, 0), (0, 0, 0, 1), s * S, static=False)
    buf.set_transform("base", "laser", (0.1, 0, 0), (0, 0, 0, 1), 0, static=True)
    for stamp in (None, 0):
        tf = buf.lookup("map", "laser", stamp)
        assert tf.stamp_ns == 2 * S
        assert tf.translation == pytest.approx((2.1, 2.0, 0.0))
    assert buf.lookup("base", "laser").stamp_ns == 0  # static only: tf2 answers at time 0
    assert buf.lookup("map", "odom").stamp_ns == 3 * S


@settings(deadline=None)  # timings on a shared machine say nothing about the maths
@given(st.integers(1, 10_000), st.integers(1, 10_000))
def test_outside_the_data_the_refusal_says_which_way_and_by_how_much(before_ms, after_ms):
    buf = TfBuffer()
    buf.set_transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    buf.set_transform("odom", "base", (0, 0, 0), (0, 0, 0, 1), 50 * S, static=False)
    buf.set_transform("odom", "base", (1, 0, 0), (0, 0, 0, 1), 51 * S, static=False)
    with pytest.raises(TfError) as past:
        buf.lookup("map", "base", 50 * S - before_ms * 1_000_000)
    assert past.value.kind == "extrapolation_past"
    assert past.value.detail["by_s"] == pytest.approx(before_ms / 1000)
    assert "into the past" in past.value.message and "[base] to frame [map]" in past.value.message
    with pytest.raises(TfError) as future:
        buf.lookup("map", "base", 51 * S + after_ms * 1_000_000)
    assert future.value.kind == "extrapolation_future"
    assert future.value.detail["by_s"] == pytest.approx(after_ms / 1000)
    assert not buf.can_transform("map", "base", 51 * S + after_ms * 1_000_000)
    assert buf.can_transform("map", "base", 50 * S + 500_000_000)


def test_unknown_and_unconnected_frames_are_refused_with_tf2s_reasons():
    buf = TfBuffer()
    buf.set_transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    buf.set_transform("world", "gps", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    with pytest.raises(TfError) as unknown:
        buf.lookup("map", "laser")
    assert unknown.value.kind == "unknown_frame"
    assert unknown.value.message == '"laser" passed to lookupTransform argument source_frame does not exist.'
    with pytest.raises(TfError) as apart:
        buf.lookup("odom", "gps")
    assert apart.value.kind == "not_connected"
    assert "not part of the same tree" in apart.value.message
    with pytest.raises(TfError) as empty:
        buf.lookup("", "odom")
    assert empty.value.kind == "invalid"
    assert buf.lookup("/map", "map").translation == (0.0, 0.0, 0.0)  # a leading slash is dropped, as tf2 does
    assert buf.lookup("world", "gps").rotation == (0.0, 0.0, 0.0, 1.0)


def test_dynamic_data_is_kept_for_the_cache_window_and_static_forever():
    buf = TfBuffer(cache_s=10.0)
    buf.set_transform("base", "laser", (0.2, 0, 0), (0, 0, 0, 1), 1 * S, static=True)
    for s in range(0, 31):
        buf.set_transform("odom", "base", (s, 0, 0), (0, 0, 0, 1), s * S, static=False)
    row = buf.frames(now_ns=30 * S)["frames"]["base"]
    assert row["oldest_stamp"] == 20.0 and row["newest_stamp"] == 30.0
    assert row["rate_hz"] == pytest.approx(1.0)
    with pytest.raises(TfError) as past:
        buf.lookup("odom", "base", 15 * S)
    assert past.value.detail["by_s"] == pytest.approx(5.0)
    assert buf.lookup("odom", "laser", 25 * S + S // 2).translation == pytest.approx((25.7, 0, 0))
    assert not buf.set_transform("odom", "base", (0, 0, 0), (0, 0, 0, 1), 5 * S, static=False)  # older than the window
    assert buf.rejected and buf.frames(now_ns=30 * S)["rejected"][0]["reason"] == "old_data"


def test_what_tf2_ignores_is_ignored_and_counted():
    buf = TfBuffer()
    assert not buf.set_transform("odom", "base", (0, 0, 0), (0, 0, 0.5, 0.5), 1 * S, static=False)
    assert not buf.set_transform("odom", "base", (math.nan, 0, 0), (0, 0, 0, 1), 1 * S, static=False)
    assert not buf.set_transform("base", "base", (0, 0, 0), (0, 0, 0, 1), 1 * S, static=False)
    with pytest.raises(TfError):
        buf.lookup("odom", "base")
    tree = buf.frames(now_ns=1 * S)
    assert {w["kind"] for w in tree["warnings"]} >= {"unnormalised"}
    assert {r["reason"] for r in tree["rejected"]} == {"unnormalised", "nan", "self_transform"}


def test_the_tree_warns_of_loops_two_parents_several_roots_stale_and_future_frames():
    buf = TfBuffer()
    buf.set_transform("a", "b", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    buf.set_transform("b", "c", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    buf.set_transform("c", "a", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    buf.set_transform("map", "odom", (0, 0, 0), (0, 0, 0, 1), 10 * S, static=False, authority="/amcl")
    buf.set_transform("world", "odom", (0, 0, 0), (0, 0, 0, 1), 10 * S, static=False, authority="/ekf")
    buf.set_transform("odom", "base", (0, 0, 0), (0, 0, 0, 1), 5 * S, static=False)
    buf.set_transform("odom", "gps", (0, 0, 0), (0, 0, 0, 1), 13 * S, static=False)
    buf.set_transform("map", "keep", (0, 0, 0), (0, 0, 0, 1), 10 * S, static=False)
    tree = buf.frames(now_ns=10 * S)
    kinds = {w["kind"]: w for w in tree["warnings"]}
    assert kinds["loop"]["frames"] == ["a", "c", "b"]  # child, its parent, its parent ...
    assert {p["authority"] for p in kinds["two_parents"]["parents"]} == {"/amcl", "/ekf"}
    assert kinds["two_parents"]["frame"] == "odom"
    assert kinds["stale"]["frame"] == "base" and kinds["stale"]["age_s"] == pytest.approx(5.0)
    assert kinds["future"]["frame"] == "gps" and kinds["future"]["ahead_s"] == pytest.approx(3.0)
    assert kinds["several_trees"]["roots"] == ["map", "world"]
    assert tree["frames"]["odom"]["parent"] == "world"  # the newest publisher wins, as in tf2
    with pytest.raises(TfError) as loop:
        buf.lookup("a", "c")
    assert loop.value.kind == "invalid" and "loop" in loop.value.message


@settings(deadline=None, max_examples=25)
@given(st.lists(st.tuples(st.integers(0, 5000), link), min_size=2, max_size=30, unique_by=lambda e: e[0]))
def test_inserting_out_of_order_is_the_same_as_in_order(entries):
    ordered, shuffled = TfBuffer(), TfBuffer()
    for stamp, (t, q) in sorted(entries):
        ordered.set_transform("odom", "base", t, q, stamp * 1_000_000, static=False)
    for stamp, (t, q) in entries:
        shuffled.set_transform("odom", "base", t, q, stamp * 1_000_000, static=False)
    stamps = sorted(s for s, _ in entries)
    for s in range(stamps[0], stamps[-1] + 1, max(1, (stamps[-1] - stamps[0]) // 7)):
        assert ordered.lookup("odom", "base", s * 1_000_000) == shuffled.lookup("odom", "base", s * 1_000_000)


def test_lookups_follow_the_tree_when_it_changes_shape():
    # Paths are kept per (target, source) between lookups: each change of shape must be seen.
    buf = TfBuffer()
    buf.set_transform("map", "odom", (1, 0, 0), (0, 0, 0, 1), 0, static=True)
    assert not buf.set_transform("odom", "base", (0, 0, 0), (0, 0, 0.5, 0.5), 0, static=True)  # refused
    with pytest.raises(TfError) as first:
        buf.lookup("map", "base")
    assert first.value.kind == "unknown_frame"
    buf.set_transform("odom", "base", (2, 0, 0), (0, 0, 0, 1), 0, static=True)  # now it has a transform
    assert buf.lookup("map", "base").translation == (3.0, 0.0, 0.0)
    buf.set_transform("world", "odom", (10, 0, 0), (0, 0, 0, 1), 0, static=True)  # re-parented
    assert buf.lookup("world", "base").translation == (12.0, 0.0, 0.0)
    with pytest.raises(TfError) as apart:
        buf.lookup("map", "base")
    assert apart.value.kind == "not_connected"
    buf.set_transform("map", "world", (0, 5, 0), (0, 0, 0, 1), 0, static=True)  # joined again
    assert buf.lookup("map", "base").translation == (12.0, 5.0, 0.0)
    buf.clear()
    with pytest.raises(TfError):
        buf.lookup("map", "base")


@settings(deadline=None)
@given(quat, st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: sum(x * x for x in v) > 1e-6),
       st.floats(1e-6, 0.06), st.floats(0.0, 1.0))
def test_between_two_close_rotations_slerp_is_still_exact(q, axis, angle, r):
    # Samples a fiftieth of a second apart differ by a few hundredths of a radian: the small-angle path.
    turn = Rotation.from_rotvec(np.array(axis) / np.linalg.norm(axis) * angle)
    b = tuple((turn * Rotation.from_quat(q)).as_quat())
    buf = TfBuffer()
    buf.set_transform("odom", "base", (0, 0, 0), q, 10 * S, static=False)
    buf.set_transform("odom", "base", (0, 0, 0), b, 11 * S, static=False)
    stamp = 10 * S + round(r * S)
    got = buf.lookup("odom", "base", stamp).rotation
    qb = np.array(b) if np.dot(q, b) >= 0 else -np.array(b)
    oracle = Slerp([0.0, 1.0], Rotation.from_quat([q, qb]))([(stamp - 10 * S) / S])
    np.testing.assert_allclose(Rotation.from_quat(got).as_matrix(), oracle.as_matrix()[0], atol=1e-7)
    assert math.isclose(sum(v * v for v in got), 1.0, abs_tol=1e-12)


def test_a_publisher_inventing_frames_is_held_at_max_frames(monkeypatch):
    from rover_web.tf import buffer as module

    monkeypatch.setattr(module, "MAX_FRAMES", 50)
    buf = TfBuffer()
    for i in range(80):
        buf.set_transform("map", f"f{i}", (0, 0, 0), (0, 0, 0, 1), 0, static=True)
    assert len(buf.frames(now_ns=0)["frames"]) == 51  # 50 children and map
    assert buf.rejected["too_many_frames"] == 30
    assert buf.set_transform("map", "f3", (1, 0, 0), (0, 0, 0, 1), 0, static=True)  # known frames still update
