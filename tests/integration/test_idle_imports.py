"""What a server loads at start, and what it leaves for first use (issue 32: idle RSS).

Each case starts a real app (rclpy, its own ROS domain) in a fresh interpreter, since what is
imported is process-wide, and then uses the feature to show it still works once loaded.
"""

import json
import subprocess
import sys

DEFERRED = ("shapely", "PIL.Image", "lz4", "zstandard", "mcap.stream_reader", "rclpy.action", "nav2_msgs.action",
            "lxml")

SCRIPT = """
import json, sys
from rover_web import create_app
config = json.loads(sys.argv[1])
app = create_app(config)
rover = app.extensions["rover_web"]
deferred = json.loads(sys.argv[2])
try:
    out = {"at_start": sorted(m for m in deferred if m in sys.modules)}
    client = app.test_client()
    if sys.argv[3] == "use":
        fence = {"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {"kind": "keep_in"},
                 "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]}}]}
        out["fence"] = client.put("/api/geofence", json=fence).status_code
        out["outside"] = client.post("/api/waypoints", json={"lng": 5.0, "lat": 5.0}).status_code
        out["nodes"] = client.get("/api/nodes").status_code
        from rover_web.view3d.service import View3dService  # a robot description comes: lxml parses it
        view3d = rover.feature(View3dService)
        view3d.on_description('<robot name="r"><link name="base_link"/></robot>', "test")
        out["urdf"] = view3d.robot()["state"]
        if sys.argv[4]:  # a floorplan with a keep-out area: a goal inside it, and its thumbnail
            name = sys.argv[4]
            out["keep_out"] = client.post(f"/api/maps/{name}/goal", json={"x": 35.0, "y": 2.0, "yaw": 0.0}).status_code
            out["thumbnail"] = client.get(f"/api/maps/{name}/thumbnail").status_code
        out["after_use"] = sorted(m for m in deferred if m in sys.modules)
    print("RESULT " + json.dumps(out))
finally:
    rover.shutdown()
"""


def run_app(tmp_path, use: bool, floorplan: str = "", **settings):
    config = {"TESTING": True, "ROVER_WEB_DB_PATH": str(tmp_path / "idle.sqlite3"),
              "ROVER_WEB_SECRET_KEY": "tests-" + "k" * 32, "ROVER_WEB_HOST": "127.0.0.1",
              "ROVER_WEB_RECORDINGS_DIR": str(tmp_path / "recordings"), **settings}
    done = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(config), json.dumps(DEFERRED),
                           "use" if use else "idle", floorplan], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    line = next(x for x in done.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line.removeprefix("RESULT "))


def test_a_robot_with_no_floorplans_loads_none_of_them_until_used(tmp_path):
    out = run_app(tmp_path, use=True, ROVER_WEB_MAPS_FILE=None)
    assert out["at_start"] == []
    # Used, each works: the fence is stored and refuses a waypoint outside it, /ros lists the graph.
    assert (out["fence"], out["outside"], out["nodes"], out["urdf"]) == (200, 422, 200, "ok")
    assert {"shapely", "rclpy.action", "lxml"} <= set(out["after_use"])


def test_the_bundled_floorplans_are_checked_at_start_by_a_child_and_loaded_when_used(tmp_path):
    # Their images and keep-out areas are checked before the server serves anything, by a child
    # process (livemap/check_maps.py): the server itself loads neither library until a page needs it.
    out = run_app(tmp_path, use=True, floorplan="Science Hall Basement")
    assert out["at_start"] == []
    # The goal inside the bundled "electrical room" is refused; the thumbnail is drawn.
    assert (out["keep_out"], out["thumbnail"]) == (422, 200)
    assert {"shapely", "PIL.Image"} <= set(out["after_use"])


def bad_catalog(tmp_path, *, image: bytes, polygon: list) -> str:
    (tmp_path / "maps").mkdir(parents=True)
    (tmp_path / "maps" / "plan.png").write_bytes(image)
    catalog = {"Plan": {"files": {"path": "", "png_file": {"file_name": "plan.png"}},
                        "yaml_parameters": {"resolution": 0.05, "origin": [0, 0, 0]},
                        "keep_out": [{"name": "bow tie", "polygon": polygon}]}}
    path = tmp_path / "maps" / "all_maps.json"
    path.write_text(json.dumps(catalog))
    return str(path)


def start_fails(tmp_path, maps_file: str) -> str:
    config = {"TESTING": True, "ROVER_WEB_DB_PATH": str(tmp_path / "idle.sqlite3"), "ROVER_WEB_MAPS_FILE": maps_file,
              "ROVER_WEB_SECRET_KEY": "tests-" + "k" * 32, "ROVER_WEB_HOST": "127.0.0.1",
              "ROVER_WEB_LIVEMAP_DEFAULT_MAP": None}
    done = subprocess.run([sys.executable, "-c", "import json, sys\nfrom rover_web import create_app\n"
                           "create_app(json.loads(sys.argv[1]))", json.dumps(config)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode != 0
    return done.stderr


def test_a_bad_floorplan_still_stops_the_server_at_start(tmp_path):
    with open("map_files/basement/basement.png", "rb") as f:
        good_png = f.read()
    # A truncated image: only decoding finds it (the child decodes it).
    truncated = bad_catalog(tmp_path / "a", image=good_png[: len(good_png) // 2],
                            polygon=[[0, 0], [1, 0], [1, 1], [0, 1]])
    assert "plan.png is not a readable image" in start_fails(tmp_path / "a", truncated)
    # A self-crossing keep-out area: only shapely's check finds it.
    bow_tie = bad_catalog(tmp_path / "b", image=good_png, polygon=[[0, 0], [1, 1], [1, 0], [0, 1]])
    assert "not a simple polygon with an area (Self-intersection" in start_fails(tmp_path / "b", bow_tie)
