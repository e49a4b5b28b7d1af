"""The simulator's map frame laid on the earth: a local tangent plane around a GPS origin. Pure Python.

The robot's fix comes from its map pose one way (enu_to_geodetic); a GPS mission's waypoints come
back the other way (geodetic_to_enu), on the same sphere, so a waypoint is reached exactly.
"""

from __future__ import annotations

import math

EARTH_RADIUS_M = 6378137.0


def enu_to_geodetic(x_east_m: float, y_north_m: float, lat0: float, lon0: float) -> tuple[float, float]:
    """Small-area approximation, good to centimetres over a few kilometres."""
    lat = lat0 + math.degrees(y_north_m / EARTH_RADIUS_M)
    lon = lon0 + math.degrees(x_east_m / (EARTH_RADIUS_M * math.cos(math.radians(lat0))))
    return lat, lon


def geodetic_to_enu(lat: float, lon: float, lat0: float, lon0: float) -> tuple[float, float]:
    """(metres east, metres north) of (lat, lon) from (lat0, lon0): enu_to_geodetic's inverse."""
    y_north = math.radians(lat - lat0) * EARTH_RADIUS_M
    x_east = math.radians(lon - lon0) * EARTH_RADIUS_M * math.cos(math.radians(lat0))
    return x_east, y_north
