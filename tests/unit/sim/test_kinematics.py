import math

from rover_web.sim.rover import DiffDrive, enu_to_geodetic


def test_straight_line_and_timeout():
    d = DiffDrive(cmd_timeout_s=0.5)
    d.command(1.0, 0.0, now=0.0)
    for i in range(1, 11):
        d.step(0.04, now=i * 0.04)
    assert math.isclose(d.x, 0.4, abs_tol=1e-9) and d.y == 0.0
    d.step(0.1, now=1.0)  # 1.0 s after the last command: the base stops by itself
    assert d.linear == 0.0
    assert math.isclose(d.x, 0.4, abs_tol=1e-9)


def test_full_circle_returns_home():
    d = DiffDrive(cmd_timeout_s=100)
    d.command(1.0, 1.0, now=0.0)
    steps = 1000
    for _ in range(steps):
        d.step(2 * math.pi / steps, now=0.0)
    assert math.isclose(d.x, 0.0, abs_tol=1e-9) and math.isclose(d.y, 0.0, abs_tol=1e-9)


def test_commands_are_clamped_and_non_finite_stops():
    d = DiffDrive(max_linear_mps=5, max_angular_rps=2)
    d.command(50, -9, now=0)
    assert (d.linear, d.angular) == (5, -2)
    d.command(float("nan"), 1, now=0)
    assert (d.linear, d.angular) == (0, 0)


def test_enu_to_geodetic_one_km_north_and_east():
    lat, lon = enu_to_geodetic(1000.0, 1000.0, 27.3742443, -82.4500873)
    assert math.isclose(lat - 27.3742443, 0.0089832, rel_tol=1e-4)
    assert math.isclose(lon + 82.4500873, 0.0089832 / math.cos(math.radians(27.3742443)), rel_tol=1e-4)
