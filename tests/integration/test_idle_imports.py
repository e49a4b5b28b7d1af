"""What a server loads at start, and what it leaves for first use (issue 32: idle RSS).

Each case starts a real app (rclpy, its own ROS domain) in a fresh interpreter, since what is
imported is process-wide, and then uses the feature to show it still works once loaded.
"""

import json
import subprocess
import sys

DEFERRED = ("shapely", "PIL.Image", "lz4", "zstandard", "mcap.stream_reader", "rclpy.action", "nav2_msgs.action")

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
        out["after_use"] = sorted(m for m in deferred if m in sys.modules)
    print("RESULT " + json.dumps(out))
finally:
    rover.shutdown()
"""


def run_app(tmp_path, use: bool, **settings):
    config = {"TESTING": True, "ROVER_WEB_DB_PATH": str(tmp_path / "idle.sqlite3"),
              "ROVER_WEB_SECRET_KEY": "tests-" + "k" * 32, "ROVER_WEB_HOST": "127.0.0.1",
              "ROVER_WEB_RECORDINGS_DIR": str(tmp_path / "recordings"), **settings}
    done = subprocess.run([sys.executable, "-c", SCRIPT, json.dumps(config), json.dumps(DEFERRED),
                           "use" if use else "idle"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    line = next(x for x in done.stdout.splitlines() if x.startswith("RESULT "))
    return json.loads(line.removeprefix("RESULT "))


def test_a_robot_with_no_floorplans_loads_none_of_them_until_used(tmp_path):
    out = run_app(tmp_path, use=True, ROVER_WEB_MAPS_FILE=None)
    assert out["at_start"] == []
    # Used, each works: the fence is stored and refuses a waypoint outside it, /ros lists the graph.
    assert (out["fence"], out["outside"], out["nodes"]) == (200, 422, 200)
    assert {"shapely", "rclpy.action"} <= set(out["after_use"])


def test_the_bundled_floorplans_are_still_checked_at_start(tmp_path):
    # Their keep-out areas and images are validated when the server starts (a bad one stops it
    # there, not at the first request), so shapely and Pillow are loaded by then.
    out = run_app(tmp_path, use=False)
    assert {"shapely", "PIL.Image"} <= set(out["at_start"])
    assert not {"lz4", "zstandard", "mcap.stream_reader", "rclpy.action", "nav2_msgs.action"} & set(out["at_start"])
