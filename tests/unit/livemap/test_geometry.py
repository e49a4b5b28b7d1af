"""World <-> pixel conversions with known values: map_server's convention, both axes, every corner."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from rover_web.livemap.geometry import MapGeometry, wrap_angle

# 800 x 480 pixels of 5 cm, lower-left corner at (-2, -1.5): 40 m wide, 24 m tall, not square.
BASEMENT = MapGeometry(800, 480, 0.05, -2.0, -1.5, 0.0)


def close(a, b, tol=1e-9):
    return all(math.isclose(x, y, abs_tol=tol) for x, y in zip(a, b, strict=True))


@pytest.mark.parametrize("world, pixel", [
    ((-2.0, -1.5), (0.0, 480.0)),     # origin = lower-left corner of the image
    ((38.0, -1.5), (800.0, 480.0)),   # lower-right
    ((-2.0, 22.5), (0.0, 0.0)),       # upper-left: image row 0 is the top
    ((38.0, 22.5), (800.0, 0.0)),     # upper-right
    ((18.0, 10.5), (400.0, 240.0)),   # centre
    ((0.0, 0.0), (40.0, 450.0)),      # the world origin, 2 m right and 1.5 m up from the corner
    ((-1.975, -1.475), (0.5, 479.5)),  # centre of the bottom-left pixel
])
def test_known_points_on_a_non_square_map_with_a_non_zero_origin(world, pixel):
    assert close(BASEMENT.world_to_pixel(*world), pixel)
    assert close(BASEMENT.pixel_to_world(*pixel), world)


def test_width_and_height_are_not_swapped():
    # 1 m east moves 20 columns, 1 m north moves 20 rows up; the image is wider than tall.
    px0, py0 = BASEMENT.world_to_pixel(0.0, 0.0)
    px1, py1 = BASEMENT.world_to_pixel(1.0, 0.0)
    px2, py2 = BASEMENT.world_to_pixel(0.0, 1.0)
    assert (px1 - px0, py1 - py0) == pytest.approx((20.0, 0.0))
    assert (px2 - px0, py2 - py0) == pytest.approx((0.0, -20.0))
    assert (BASEMENT.width_m, BASEMENT.height_m) == pytest.approx((40.0, 24.0))
    assert BASEMENT.contains(37.9, 0.0) and not BASEMENT.contains(0.0, 23.0)


def test_contains_and_cell_of_at_the_edges():
    assert BASEMENT.contains(-2.0, -1.5) and BASEMENT.contains(38.0, 22.5)
    assert not BASEMENT.contains(-2.001, 0.0) and not BASEMENT.contains(0.0, 22.501)
    assert BASEMENT.cell_of(-1.99, -1.49) == (0, 479)   # bottom-left cell
    assert BASEMENT.cell_of(37.99, 22.49) == (799, 0)   # top-right cell
    assert BASEMENT.cell_of(38.0, 0.0) is None          # the far edge belongs to no cell


def test_cm_per_pixel_scales_the_display():
    assert BASEMENT.cm_per_pixel == pytest.approx(5.0)
    assert BASEMENT.display_scale(2.0) == pytest.approx(2.5)   # 2 cm per display pixel: 2.5x bigger
    assert BASEMENT.display_scale(10.0) == pytest.approx(0.5)
    assert close(BASEMENT.to_display(18.0, 10.5, 2.0), (1000.0, 600.0))
    assert close(BASEMENT.to_display(38.0, -1.5, 10.0), (400.0, 240.0))
    assert close(BASEMENT.from_display(1000.0, 600.0, 2.0), (18.0, 10.5))


def test_origin_yaw_rotates_the_image_axes_like_rviz():
    # Rotated +90 degrees: the image's columns run along world +y, its rows (upwards) along world -x.
    g = MapGeometry(100, 50, 0.1, 1.0, 2.0, math.pi / 2)
    assert close(g.world_to_pixel(1.0, 2.0), (0.0, 50.0))        # the origin is still the lower-left corner
    assert close(g.world_to_pixel(1.0, 12.0), (100.0, 50.0))     # 10 m along +y = the full width
    assert close(g.world_to_pixel(-4.0, 2.0), (0.0, 0.0))        # 5 m along -x = the full height
    assert close(g.pixel_to_world(100.0, 0.0), (-4.0, 12.0))
    assert g.yaw_to_image(math.pi / 2) == pytest.approx(0.0)     # facing +y is facing along the columns
    assert g.contains(0.0, 5.0) and not g.contains(2.0, 5.0)


def test_invalid_geometry_is_refused():
    for args in ((0, 10, 0.05), (10, 10, 0.0), (10, 10, float("nan")), (10, 10, 0.05, float("inf"))):
        with pytest.raises(ValueError):
            MapGeometry(*args)


def test_wrap_angle():
    assert wrap_angle(3 * math.pi / 2) == pytest.approx(-math.pi / 2)
    assert wrap_angle(-math.pi) == pytest.approx(math.pi)
    assert wrap_angle(0.25) == 0.25


coordinates = st.floats(min_value=-1e4, max_value=1e4, allow_nan=False)


@given(x=coordinates, y=coordinates,
       width=st.integers(1, 5000), height=st.integers(1, 5000),
       resolution=st.floats(min_value=0.001, max_value=1.0),
       ox=coordinates, oy=coordinates, oyaw=st.floats(min_value=-math.pi, max_value=math.pi))
def test_round_trip_world_pixel_world(x, y, width, height, resolution, ox, oy, oyaw):
    g = MapGeometry(width, height, resolution, ox, oy, oyaw)
    back = g.pixel_to_world(*g.world_to_pixel(x, y))
    assert close(back, (x, y), tol=1e-6)


@given(px=st.floats(min_value=0, max_value=800), py=st.floats(min_value=0, max_value=480),
       cm=st.floats(min_value=0.1, max_value=100))
def test_round_trip_display_world_display(px, py, cm):
    world = BASEMENT.from_display(px, py, cm)
    assert close(BASEMENT.to_display(*world, cm), (px, py), tol=1e-6)
