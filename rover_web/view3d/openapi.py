"""The 3D view's routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import header, obj, op, page, path, query

ERROR = obj({"message": {"type": "string"}, "line": {"type": ["integer", "null"]},
             "column": {"type": ["integer", "null"]}})

PATHS = {
    "/3d": {"get": page("The 3D view: the robot's model moved by TF, TF axes, markers, the point cloud",
                        tag="pages")},
    "/api/3d/robot": {
        "get": op("The robot's description: state waiting, ok (the URDF text, its links, joints and meshes) or "
                  "error (the parser's message and the line it comes from)", tag="view3d",
                  ok=obj({"state": {"type": "string", "enum": ["waiting", "ok", "error"]},
                          "source": {"type": ["string", "null"]}, "seq": {"type": "integer"},
                          "name": {"type": "string"}, "root": {"type": "string"},
                          "links": {"type": "array", "items": {"type": "string"}},
                          "joints": {"type": "array", "items": obj(closed=False)},
                          "meshes": {"type": "array", "items": obj(closed=False)},
                          "urdf": {"type": "string"}, "error": ERROR, "message": {"type": "string"},
                          "base_frame": {"type": "string"}, "map_frame": {"type": "string"},
                          "odom_frame": {"type": "string"}, "tf": {"type": "boolean"},
                          "tf_missing": {"type": ["string", "null"]},
                          "pose_hz": {"type": "number"}, "cloud_topic": {"type": ["string", "null"]},
                          "markers_topic": {"type": ["string", "null"]},
                          "markers_skipped": obj(closed=False, description="markers not drawn, by reason"),
                          "cloud": obj(closed=False,
                                       description="clouds received, sent, skipped by reason")}, required=("state",)),
                  errors={}),
    },
    "/api/3d/mesh/{package}/{path}": {
        "get": op("A mesh (STL, Collada, OBJ) or its texture from inside a package's share folder, found through "
                  "the ament index; cached as immutable (ETag, If-None-Match answers 304)", tag="view3d",
                  ok={"type": "string", "format": "binary"}, media="application/octet-stream",
                  params=[path("package", {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"},
                               "the package of a package:// URI"),
                          path("path", {"type": "string"}, "the file's path inside the package's share folder"),
                          header("If-None-Match", {"type": "string"}, "the ETag the browser holds")],
                  errors={400: "bad_package, bad_mesh_path", 403: "outside_package ('..', or a symlink leading "
                          "out of the share folder)", 404: "unknown_package, no_such_mesh",
                          415: "not_a_mesh"}),
    },
    "/api/3d/cloud": {
        "get": op("The newest point cloud past sequence `after`, thinned on a voxel grid to at most "
                  "ROVER_WEB_POINTCLOUD_MAX_POINTS: a u32 header length, a JSON header (seq, frame_id, stamp, "
                  "count, intensity, extent, voxel_m, source_points), count x,y,z float32 triples, then count "
                  "float32 intensities when the header says so; 204 when none came within `wait` seconds",
                  tag="view3d", ok={"type": "string", "format": "binary"}, media="application/octet-stream",
                  params=[query("after", {"type": "integer", "minimum": 0}, "the last sequence the page has (0)"),
                          query("wait", {"type": "number", "minimum": 0, "maximum": 2},
                                "seconds to wait for a newer cloud (0: answer at once)")],
                  errors={400: "bad_after, bad_wait", 401: "revoked (the credentials ended while it waited)",
                          404: "no_cloud_topic",
                          503: "too_many_streams (while waiting it holds a stream slot)"},
                  cross_site=True),
    },
}
