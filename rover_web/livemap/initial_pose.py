"""The operator's initial pose (RViz's "2D Pose Estimate"): checked here, published by the service.

AMCL (and slam_toolbox's localization mode) re-seed their estimate from a
geometry_msgs/PoseWithCovarianceStamped on /initialpose. The covariance says how sure the operator
is; without one we send RViz's own: 0.5 m standard deviation in x and y, 15 degrees in yaw.
"""

from __future__ import annotations

import math

from rover_web.web.validate import InvalidInput, number, only_keys

SIDE = 6  # x, y, z, roll, pitch, yaw
RVIZ_COVARIANCE = tuple(0.25 if i in (0, 7) else (math.pi / 12) ** 2 if i == 35 else 0.0 for i in range(36))
MAX_VARIANCE = 1e6  # (1 km)^2 or (1000 rad)^2: beyond it the number is a mistake, not doubt
SYMMETRY_TOLERANCE = 1e-9


def covariance(value) -> tuple[float, ...]:
    """A 6x6 row-major covariance (x, y, z, roll, pitch, yaw) as ROS carries it; InvalidInput if not one."""
    if not isinstance(value, list) or len(value) != SIDE * SIDE:
        raise InvalidInput("'covariance' must be an array of 36 numbers: the 6x6 matrix (x, y, z, roll, pitch, "
                           "yaw) row by row", "bad_type")
    cells = []
    for i, v in enumerate(value):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InvalidInput("'covariance[%(i)s]' must be a number", "bad_type", i=i)
        try:
            v = float(v)
        except OverflowError:
            raise InvalidInput("'covariance[%(i)s]' is out of range", "out_of_range", i=i) from None
        if not math.isfinite(v):
            raise InvalidInput("'covariance[%(i)s]' must be finite", "non_finite", i=i)
        if abs(v) > MAX_VARIANCE:
            raise InvalidInput("'covariance[%(i)s]' must be within ±%(max_variance)s", "out_of_range",
                               i=i, max_variance=format(MAX_VARIANCE, "g"))
        cells.append(v)
    for row in range(SIDE):
        if cells[row * SIDE + row] < 0:
            raise InvalidInput(
                "'covariance[%(value)s]' is a variance on the diagonal: it cannot be negative",
                "out_of_range",
                value=row * SIDE + row,
            )
        for col in range(row + 1, SIDE):
            a, b = cells[row * SIDE + col], cells[col * SIDE + row]
            if abs(a - b) > SYMMETRY_TOLERANCE * max(1.0, abs(a), abs(b)):
                raise InvalidInput(
                    "'covariance' must be symmetric: [%(value)s] is %(a)s but [%(value2)s] is %(b)s",
                    "bad_value",
                    value=row * SIDE + col,
                    a=format(a, "g"),
                    value2=col * SIDE + row,
                    b=format(b, "g"),
                )
    return tuple(cells)


def parse(body: dict) -> tuple[float, float, float, tuple[float, ...]]:
    """(x, y, yaw, covariance) of a POST /api/maps/<name>/initial_pose body; InvalidInput otherwise."""
    only_keys(body, {"x", "y", "yaw", "covariance"})
    x = number(body, "x")
    y = number(body, "y")
    yaw = number(body, "yaw", default=0.0)
    cov = covariance(body["covariance"]) if body.get("covariance") is not None else RVIZ_COVARIANCE
    return x, y, yaw, cov
