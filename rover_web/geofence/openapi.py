"""The geofence's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

FEATURE = obj({
    "type": {"const": "Feature"},
    "geometry": obj({"type": {"enum": ["Polygon", "MultiPolygon"]}, "coordinates": {"type": "array"}},
                    ("type", "coordinates")),
    "properties": obj({"kind": {"enum": ["keep_in", "keep_out"]}, "name": {"type": "string"}}, ("kind",),
                      closed=False),
}, ("type", "geometry", "properties"), closed=False)
COLLECTION = obj({"type": {"const": "FeatureCollection"}, "features": {"type": "array", "items": FEATURE}},
                 ("type", "features"), closed=False)

PATHS = {
    "/api/geofence": {
        "get": op("The enforced geofence, as a GeoJSON FeatureCollection", tag="geofence", ok=COLLECTION),
        "put": op("Replace the geofence (keep_in and keep_out Polygons and MultiPolygons)", tag="geofence",
                  role="admin", body=COLLECTION, ok=COLLECTION,
                  errors={400: "bad_json, bad_geojson, bad_type, invalid_geometry, out_of_range "
                               "(self-intersecting rings, too many vertices, across the antimeridian)",
                          503: "storage_unavailable", 507: "disk_full"}),
    },
}
