"""The geofence's rules: inside, outside, on the edge, holes, legs, and which fences are refused."""

import pytest

from rover_web.geofence.rules import Fence, OutsideGeofence, parse_fence
from rover_web.web.validate import InvalidInput


def ring(*points):
    return [list(p) for p in points] + [list(points[0])]


def square(x0, y0, x1, y1):
    return ring((x0, y0), (x1, y0), (x1, y1), (x0, y1))


def feature(kind, *rings, name=None, multi=False):
    properties = {"kind": kind} | ({"name": name} if name else {})
    geometry = {"type": "MultiPolygon", "coordinates": [list(rings)]} if multi else \
        {"type": "Polygon", "coordinates": list(rings)}
    return {"type": "Feature", "properties": properties, "geometry": geometry}


def fence(*features, max_vertices=1000) -> Fence:
    return parse_fence({"type": "FeatureCollection", "features": list(features)}, max_vertices)


# A 10 x 10 keep-in with a 2 x 2 hole at (1..3, 1..3), and a keep-out at (6..8, 6..8) with an
# open island at (6.5..7.5, 6.5..7.5).
FENCE = fence(feature("keep_in", square(0, 0, 10, 10), square(1, 1, 3, 3), name="lake"),
              feature("keep_out", square(6, 6, 8, 8), square(6.5, 6.5, 7.5, 7.5), name="dock"))


@pytest.mark.parametrize("point, reason", [
    ((5, 5), None),                          # inside the keep-in
    ((11, 5), "outside_keep_in"),            # outside it
    ((-0.0001, 5), "outside_keep_in"),
    ((2, 2), "outside_keep_in"),             # in the keep-in's hole
    ((7, 6.2), "inside_keep_out"),           # in the keep-out
    ((7, 7), None),                          # in the keep-out's hole: the open island
])
def test_inside_outside_and_holes(point, reason):
    refused = FENCE.refusal(*point)
    assert (refused.details["reason"] if refused else None) == reason


@pytest.mark.parametrize("point, allowed", [
    ((0, 5), True),        # on the keep-in's outline: inside it
    ((10, 10), True),      # on its corner
    ((3, 2), True),        # on its hole's edge: the edge belongs to the polygon
    ((6, 7), False),       # on the keep-out's outline: inside the keep-out
    ((8, 8), False),       # on its corner
    ((6.5, 7), False),     # on its island's edge: still the keep-out's
])
def test_on_the_edge(point, allowed):
    assert FENCE.allows(*point) is allowed


def test_a_keep_out_refusal_names_the_area():
    with pytest.raises(OutsideGeofence) as refused:
        FENCE.check_point(7, 6.2)
    assert refused.value.details == {"reason": "inside_keep_out", "lng": 7, "lat": 6.2, "feature": 1, "name": "dock"}
    assert "'dock'" in str(refused.value)


def test_no_keep_in_means_everywhere_but_the_keep_outs():
    only_out = fence(feature("keep_out", square(0, 0, 1, 1)))
    assert only_out.allows(50, 50) and not only_out.allows(0.5, 0.5)
    assert Fence().allows(0, 0) and Fence().empty


def test_several_keep_ins_are_a_union_and_multipolygons_count():
    two = fence(feature("keep_in", square(0, 0, 1, 1)),
                feature("keep_in", square(5, 5, 6, 6), multi=True))
    assert two.allows(0.5, 0.5) and two.allows(5.5, 5.5) and not two.allows(3, 3)


@pytest.mark.parametrize("route, reason, leg", [
    ([(0.5, 5), (9.5, 5)], None, None),                     # straight across the lake
    ([(5, 5), (9, 9)], "leg_crosses_keep_out", [0, 1]),     # through the dock
    ([(5, 7), (5.99, 9.5)], None, None),                     # beside it
    ([(5, 5), (5, 7), (7, 9)], "leg_crosses_keep_out", [1, 2]),  # touches only its corner (6, 8)
    ([(5, 0.5), (0.5, 5)], "leg_leaves_keep_in", [0, 1]),   # clips the hole at (1..3, 1..3)
    ([(9, 1), (9.5, 9.5), (11, 9.5)], "outside_keep_in", None),  # a waypoint outside is named first
    ([(1, 9), (9, 9.5), (9.5, 0.5), (4, 0.5)], None, None),
])
def test_legs(route, reason, leg):
    try:
        FENCE.check_route(route)
        refused = None
    except OutsideGeofence as exc:
        refused = exc.details
    assert (refused["reason"] if refused else None) == reason
    if leg:
        assert refused["leg"] == leg


def test_a_leg_that_leaves_a_concave_keep_in_between_two_inside_points():
    u_shape = fence(feature("keep_in", ring((0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3))))
    assert u_shape.allows(0.5, 2.5) and u_shape.allows(2.5, 2.5)
    with pytest.raises(OutsideGeofence) as refused:
        u_shape.check_route([(0.5, 2.5), (2.5, 2.5)])
    assert refused.value.details["reason"] == "leg_leaves_keep_in"


# --- which documents are fences ---

def refusal(doc, max_vertices=1000) -> InvalidInput:
    with pytest.raises(InvalidInput) as refused:
        parse_fence(doc, max_vertices)
    return refused.value


def collection(*features):
    return {"type": "FeatureCollection", "features": list(features)}


def test_a_self_intersecting_ring_is_refused_naming_the_feature():
    bowtie = ring((0, 0), (1, 1), (1, 0), (0, 1))
    exc = refusal(collection(feature("keep_in", square(0, 0, 9, 9)), feature("keep_out", bowtie, name="bow")))
    assert exc.code == "invalid_geometry"
    assert "features[1] ('bow')" in str(exc) and "Self-intersection" in str(exc)


@pytest.mark.parametrize("doc, code, words", [
    ([], "bad_geojson", "FeatureCollection"),
    ({"type": "Feature"}, "bad_geojson", "FeatureCollection"),
    ({"type": "FeatureCollection"}, "bad_geojson", "features"),
    (collection({"type": "Feature", "properties": {"kind": "keep_in"},
                 "geometry": {"type": "Point", "coordinates": [0, 0]}}), "bad_geojson", "Polygon or MultiPolygon"),
    (collection(feature("keep_near", square(0, 0, 1, 1))), "bad_geojson", "kind"),
    (collection({"type": "Feature", "geometry": {"type": "Polygon", "coordinates": [square(0, 0, 1, 1)]}}),
     "bad_geojson", "properties"),
    (collection(feature("keep_in", [[0, 0], [1, 0], [1, 1], [0, 1]])), "bad_geojson", "not closed"),
    (collection(feature("keep_in", [[0, 0], [1, 0], [0, 0]])), "bad_geojson", "at least 4"),
    (collection(feature("keep_in", square(0, 0, 1, 100))), "out_of_range", "lat"),
    (collection(feature("keep_in", ring((0, 0), ("1", 0), (1, 1)))), "bad_type", "lng"),
    (collection(feature("keep_in", ring((0, 0), (1, 0), (2, 0)))), "invalid_geometry", "features[0]"),
    (collection(feature("keep_in", square(0, 0, 1, 1), name=7)), "bad_geojson", "name"),
])
def test_invalid_geojson_is_refused(doc, code, words):
    exc = refusal(doc)
    assert exc.code == code and words in str(exc)


def test_the_antimeridian_is_refused():
    across = ring((179.5, 10), (-179.5, 10), (-179.5, 11), (179.5, 11))
    exc = refusal(collection(feature("keep_in", across)))
    assert exc.code == "antimeridian" and "antimeridian" in str(exc)
    # The same area written the long way round is wider than 180 degrees: refused too, not a band
    # around the world.
    wide = ring((-179.5, 10), (0, 10), (179.5, 10), (179.5, 11), (0, 11), (-179.5, 11))
    assert refusal(collection(feature("keep_in", wide))).code == "antimeridian"
    # Up to the line itself is fine.
    assert parse_fence(collection(feature("keep_in", square(170, 10, 180, 11))), 100).allows(180, 10.5)


def test_the_vertex_cap_counts_every_ring_of_every_feature():
    doc = collection(feature("keep_in", square(0, 0, 10, 10), square(1, 1, 2, 2)),
                     feature("keep_out", square(5, 5, 6, 6)))
    assert len(parse_fence(doc, 15).areas) == 2  # 3 rings x 5 positions
    exc = refusal(doc, max_vertices=14)
    assert exc.code == "too_many_vertices" and "ROVER_WEB_GEOFENCE_MAX_VERTICES" in str(exc)


def test_round_trip_keeps_names_and_drops_altitude():
    doc = collection(feature("keep_in", [[0, 0, 5], [1, 0, 5], [1, 1, 5], [0, 0, 5]], name="pond"))
    out = parse_fence(doc, 100).to_geojson()
    assert out["features"][0]["properties"] == {"kind": "keep_in", "name": "pond"}
    assert out["features"][0]["geometry"]["coordinates"] == [[[0, 0], [1, 0], [1, 1], [0, 0]]]
    assert parse_fence(out, 100).to_geojson() == out
