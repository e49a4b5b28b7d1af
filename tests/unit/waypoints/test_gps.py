"""The robot's fix on the map: no lock or a broken position is "no fix", never a point at 0,0."""

import math

import pytest

from rover_web.waypoints.gps import FixReading, GpsTrack, distance_m

LAT, LNG = 27.3742443, -82.4500873


def reading(lat=LAT, lng=LNG, status=0, alt=1.0, sigma=0.7):
    return FixReading(status=status, lat=lat, lng=lng, alt=alt, horizontal_sigma_m=sigma)


def test_a_good_fix_is_plotted_and_starts_the_track():
    state = GpsTrack().update(reading())
    assert state["fix"] is True and state["reason"] is None
    assert (state["lng"], state["lat"], state["alt"], state["accuracy_m"]) == (LNG, LAT, 1.0, 0.7)
    assert state["track"] == [[LNG, LAT]]


@pytest.mark.parametrize("bad, reason", [
    (dict(status=-1), "no satellite lock"),
    (dict(status=-2, lat=0.0, lng=0.0), "no satellite lock"),
    (dict(lat=math.nan), "finite"),
    (dict(lng=math.inf), "finite"),
    (dict(lat=91.0), "range"),
    (dict(lng=-181.0), "range"),
])
def test_no_fix_is_not_plotted_and_keeps_the_track(bad, reason):
    track = GpsTrack()
    track.update(reading())
    state = track.update(reading(**bad))
    assert state["fix"] is False and reason in state["reason"]
    assert state["lng"] is None and state["lat"] is None and state["alt"] is None
    assert state["track"] == [[LNG, LAT]]  # the bad reading added nothing


def test_non_finite_altitude_or_accuracy_do_not_reach_json():
    state = GpsTrack().update(reading(alt=math.nan, sigma=None))
    assert state["fix"] is True and state["alt"] is None and state["accuracy_m"] is None


def test_the_track_grows_only_with_movement_and_stays_bounded():
    track = GpsTrack(max_points=5, min_step_m=0.5)
    for _ in range(10):
        track.update(reading())  # parked: one point
    assert len(track.state()["track"]) == 1
    step_deg = 1.0 / 111_195  # about a metre of latitude
    for i in range(1, 20):
        track.update(reading(lat=LAT + i * step_deg))
    points = track.state()["track"]
    assert len(points) == 5
    assert points[-1] == [LNG, round(LAT + 19 * step_deg, 8)]


def test_distance():
    assert distance_m(LNG, LAT, LNG, LAT + 1.0 / 111_195) == pytest.approx(1.0, rel=1e-3)
    assert distance_m(0, 0, 1, 0) == pytest.approx(111_195, rel=1e-3)
