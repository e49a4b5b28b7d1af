"""Plots: field paths, numeric fields of a type, decimation that keeps min and max, bounded rings."""

import math

import pytest

from rover_web.plot.field import FieldError, finite, parse_path, read_number
from rover_web.plot.series import SeriesRing, decimate


def test_paths_with_nested_fields_and_array_indices():
    assert parse_path("twist.twist.linear.x") == ("twist", "twist", "linear", "x")
    assert parse_path("position[2]") == ("position", 2)
    assert parse_path("a[1][2].b") == ("a", 1, 2, "b")


@pytest.mark.parametrize("bad", ["", ".x", "x.", "x[]", "x[-1]", "x[1", "1x", "x y", "x\n", "x.__class__()", "a" * 300])
def test_malformed_paths_are_refused(bad):
    with pytest.raises(FieldError):
        parse_path(bad)


class Obj:
    def __init__(self, **kw):
        self.__dict__.update(kw)


def test_reading_a_number_and_a_missing_element():
    msg = Obj(pose=Obj(position=[1.0, 2.0, 3.5]), flag=True, b=b"\x07")
    assert read_number(msg, parse_path("pose.position[2]")) == 3.5
    assert read_number(msg, parse_path("pose.position[9]")) is None
    assert read_number(msg, ("flag",)) == 1.0 and read_number(msg, ("b",)) == 7.0
    assert not finite(math.nan) and not finite(math.inf) and not finite(None) and finite(0.0)


def test_decimation_keeps_at_most_2000_points_and_every_spike():
    n = 100_000
    t = [i * 0.01 for i in range(n)]
    v = [0.0] * n
    v[12_345] = 50.0
    v[77_777] = -40.0
    dt, dv = decimate(t, v)
    assert len(dt) <= 2000
    assert max(dv) == 50.0 and min(dv) == -40.0
    assert dt == sorted(dt) and dt[0] == 0.0
    assert decimate([1.0, 2.0], [3.0, 4.0]) == ([1.0, 2.0], [3.0, 4.0])


def test_a_series_ring_is_bounded_and_windows_by_time():
    ring = SeriesRing(keep=1000)
    ring.add_many([(float(i), float(i)) for i in range(5000)])
    assert len(ring) == 1000
    t, v, decimated = ring.window(since=4990.0)
    assert t == [float(i) for i in range(4990, 5000)] and not decimated
    t, v, decimated = ring.window(since=0.0, max_points=100)
    assert len(t) <= 100 and decimated and t[-1] == 4999.0
