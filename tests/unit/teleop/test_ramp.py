"""The deadman's hold, ramp and hard bound as a function of age (ramp.py)."""

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rover_web.teleop.ramp import Ramp


def test_hold_then_a_linear_ramp_then_zero_at_the_bound():
    ramp = Ramp(0.3, 1.0)
    assert [ramp.factor(a) for a in (0.0, 0.1, 0.3)] == [1.0, 1.0, 1.0]
    assert ramp.factor(0.65) == pytest.approx(0.5)
    assert ramp.factor(0.3 + 0.7 * 0.9) == pytest.approx(0.1)
    assert ramp.factor(1.0) == 0.0 and ramp.factor(5.0) == 0.0
    assert not ramp.expired(0.999) and ramp.expired(1.0) and ramp.expired(1e9)
    assert ramp.scaled(2.0, -1.0, 0.65) == pytest.approx((1.0, -0.5))  # both axes alike: the arc is kept


def test_no_ramp_when_the_bound_is_the_hold():
    ramp = Ramp(0.3, 0.3)
    assert ramp.factor(0.2999) == 1.0 and ramp.factor(0.3) == 0.0 and ramp.expired(0.3)


def test_an_age_nobody_can_vouch_for_is_past_the_bound():
    ramp = Ramp(0.3, 1.0)
    assert ramp.factor(math.nan) == 0.0 and ramp.expired(math.nan)
    assert ramp.factor(math.inf) == 0.0
    assert ramp.factor(-1.0) == 1.0  # not yet aged: the command as given, never more


@pytest.mark.parametrize("hold, bound", [(0.0, 1.0), (0.5, 0.3), (math.nan, 1.0), (0.3, math.inf), (-1, 1)])
def test_nonsense_is_refused(hold, bound):
    with pytest.raises(ValueError):
        Ramp(hold, bound)


@settings(max_examples=300, deadline=None)
@given(hold=st.floats(0.01, 5), extra=st.floats(0, 5),
       ages=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1, max_size=40),
       linear=st.floats(-100, 100), angular=st.floats(-100, 100))
def test_the_published_speed_is_finite_never_above_the_command_and_only_falls(hold, extra, ages, linear, angular):
    ramp = Ramp(hold, hold + extra)
    previous = math.inf
    for age in sorted(a for a in ages if not math.isnan(a)):
        f = ramp.factor(age)
        assert math.isfinite(f) and 0.0 <= f <= 1.0
        assert f <= previous
        previous = f
        lin, ang = ramp.scaled(linear, angular, age)
        assert math.isfinite(lin) and math.isfinite(ang)
        assert abs(lin) <= abs(linear) and abs(ang) <= abs(angular)
        assert (lin == 0 or math.copysign(1, lin) == math.copysign(1, linear))  # it slows, never reverses
        if age >= ramp.bound_s:
            assert f == 0.0
