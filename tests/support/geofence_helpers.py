"""Fences for the geofence tests: a keep-in square with a keep-out square inside it."""

from __future__ import annotations

from rover_web.geofence.rules import parse_fence
from rover_web.geofence.service import breach_message
from rover_web.web.api_messages import Text


def square(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]


def area(kind: str, *rings, name: str | None = None) -> dict:
    return {"type": "Feature", "properties": {"kind": kind} | ({"name": name} if name else {}),
            "geometry": {"type": "Polygon", "coordinates": list(rings)}}


def collection(*features) -> dict:
    return {"type": "FeatureCollection", "features": list(features)}


# Keep in 0..1 x 0..1 degrees, keep out of 0.6..0.8 x 0.6..0.8 (the "dock"). The waypoint tests'
# warm-up point (0.5, 0.5) is allowed.
FENCE = collection(area("keep_in", square(0, 0, 1, 1), name="lake"),
                   area("keep_out", square(0.6, 0.6, 0.8, 0.8), name="dock"))
INSIDE = (0.3, 0.3)
OUTSIDE = (1.5, 0.5)
IN_KEEP_OUT = (0.7, 0.7)

# A keep-out square "dock" over 0..1 x 0..1 alone: its centre (0.5, 0.5) is a breach (the language tests).
DOCK = collection(area("keep_out", square(0, 0, 1, 1), name="dock"))


def breach_at(doc: dict, lng: float, lat: float) -> Text:
    """The banner's sentence for a robot at (lng, lat) outside the fence `doc`, as the service says it."""
    return breach_message(parse_fence(doc, 1000).refusal(lng, lat))
