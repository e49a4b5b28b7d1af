"""The offline tiles route, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import obj, op

PATHS = {
    "/tiles/{z}/{x}/{y}": {
        "get": op("One basemap tile from the installed MBTiles file", tag="basemap",
                  media="image/png", ok={"type": "string", "contentMediaType": "image/png"},
                  errors={404: "no such tile, or no basemap installed (an empty body)"},
                  extra={"x-also-media": ["image/jpeg", "image/webp", "application/x-protobuf"]}),
    },
    "/basemap/{name}": {
        "get": op("A drawn basemap: a GeoJSON FeatureCollection of land, water, paths...", tag="basemap",
                  media="application/geo+json", ok=obj(closed=False),
                  errors={404: "unknown_basemap"}),
    },
}
