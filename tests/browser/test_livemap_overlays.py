"""LiveMap's overlays in Chromium, fed by a real ROS publisher in another process: each layer is
drawn where its map coordinates say (pixel checks on the canvas), and each one's checkbox hides it
and is remembered across a reload."""

import math
import time

import pytest
import requests

from tests.browser.test_livemap import BASEMENT, CATALOG, B, amcl, canvas_rgb, open_map, state

pytestmark = [pytest.mark.browser, pytest.mark.ros]

SCAN = "sensor_msgs/msg/LaserScan"
GRID = "nav_msgs/msg/OccupancyGrid"
MARKERS = "visualization_msgs/msg/MarkerArray"
POLYGON = "geometry_msgs/msg/PolygonStamped"
AMCL = "geometry_msgs/msg/PoseWithCovarianceStamped"
SCAN_RGB = (255, 59, 48)
FOOTPRINT_RGB = (227, 179, 65)
PATH_RGB = (88, 166, 255)
MARKER_RGB = (0, 255, 0)


def screen(s, x, y):
    px, py = CATALOG[BASEMENT].geometry.world_to_pixel(x, y)
    return s["view"]["offsetX"] + px * s["view"]["scale"], s["view"]["offsetY"] + py * s["view"]["scale"]


def scan_msg():
    ranges = [float("inf")] * 360
    ranges[180] = 2.0                  # angle 0: straight ahead of a robot facing +x
    ranges[90] = float("nan")
    return {"header": {"frame_id": "base_scan"}, "angle_min": -math.pi, "angle_max": math.pi - math.pi / 180,
            "angle_increment": math.pi / 180, "range_min": 0.05, "range_max": 20.0, "ranges": ranges}


def grid_msg():
    cells = []
    for row in range(40):                 # row 0 at the origin (south)
        # The west half lethal; the east half free in the south and inscribed (99) in the north.
        cells += [100] * 20 + ([0] * 20 if row < 20 else [99] * 20)
    return {"header": {"frame_id": "map"},
            "info": {"width": 40, "height": 40, "resolution": 0.05,
                     "origin": {"position": {"x": 10.0, "y": 10.0}, "orientation": {"w": 1.0}}},
            "data": cells}


def markers_msg():
    sphere = {"header": {"frame_id": "map"}, "ns": "t", "id": 1, "type": 2, "action": 0,
              "pose": {"position": {"x": 26.0, "y": 17.0}, "orientation": {"w": 1.0}},
              "scale": {"x": 1.0, "y": 1.0, "z": 1.0}, "color": {"g": 1.0, "a": 1.0}}
    label = {**sphere, "id": 2, "type": 9, "text": "sensed",
             "pose": {"position": {"x": 26.0, "y": 19.0}, "orientation": {"w": 1.0}}}
    return {"markers": [sphere, label]}


def footprint_msg():
    square = [(15.0, 7.0), (17.0, 7.0), (17.0, 9.0), (15.0, 9.0)]
    return {"header": {"frame_id": "map"}, "polygon": {"points": [{"x": x, "y": y} for x, y in square]}}


@pytest.fixture
def sensing(ros_peer):
    peer = ros_peer("overlay_publisher")
    for topic, kind, qos in (("/amcl_pose", AMCL, "latched"), ("/scan", SCAN, "sensor_data"),
                             ("/global_costmap/costmap", GRID, "latched"),
                             ("/visualization_marker_array", MARKERS, "default"),
                             ("/global_costmap/published_footprint", POLYGON, "default")):
        peer.advertise(topic, kind, qos=qos)
    return peer


def feed_until_drawn(page, peer, timeout=20):
    """Publish every layer until the page has drawn each (discovery and the first frames take a moment)."""
    deadline = time.monotonic() + timeout
    while True:
        peer.publish("/amcl_pose", amcl(23.0, 8.0, 0.0))
        peer.publish("/scan", scan_msg())
        peer.publish("/global_costmap/costmap", grid_msg())
        peer.publish("/visualization_marker_array", markers_msg())
        peer.publish("/global_costmap/published_footprint", footprint_msg())
        try:
            page.wait_for_function("""(() => { const l = window.liveMapState.layers;
                return l && l.scan && l.scan.points === 1 && l.costmaps.length === 1 && l.markers === 2
                       && l.footprint === 4 && window.liveMapState.pose && window.liveMapState.pose.y === 8; })()""",
                                   timeout=1500)
            page.wait_for_timeout(200)   # one more frame after the last value
            return state(page)
        except Exception:
            if time.monotonic() > deadline:
                raise


def pixel(page, s, x, y):
    sx, sy = screen(s, x, y)
    return canvas_rgb(page, math.floor(sx), math.floor(sy))


def toggle(page, layer, on):
    box = page.locator(f'input[data-layer="{layer}"]')
    box.check() if on else box.uncheck()
    page.wait_for_function(f"window.liveMapState.layers.shown.{layer} === {'true' if on else 'false'}")
    page.wait_for_timeout(100)


def test_every_overlay_is_drawn_where_its_coordinates_say_and_each_toggles(live_server, page, sensing):
    # A path for the pose history first: the robot drove north along x = 20, then to its spot.
    sensing.wait_match("/amcl_pose")
    # Each pose until the server holds it: the subscription keeps the last one (AMCL's own depth), so a
    # loaded executor may take only the newest of two; the same pose again adds nothing to the trail.
    # The page reads the history once, then adds live poses: it is opened when the whole drive is held.
    deadline = time.monotonic() + 15
    for i, y in enumerate((2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5, 6.0)):
        sensing.publish("/amcl_pose", amcl(20.0, y))
        while len(requests.get(f"{live_server.url}/api/overlays", timeout=5).json()["trail"]) < i + 1:
            assert time.monotonic() < deadline, "the server never held the nine poses published"
            time.sleep(0.1)
            sensing.publish("/amcl_pose", amcl(20.0, y))
    open_map(page, live_server.url)
    s = feed_until_drawn(page, sensing)
    layers = s["layers"]
    assert layers["scan"] == {"points": 1, "far": 0, "beams": 360, "placed_by": "configured"}  # no TF: the offsets
    # Scan: the one return lies 2 m ahead of the robot at (23, 8), facing +x.
    assert pixel(page, s, 25.0, 8.0) == SCAN_RGB
    # Costmap: the lethal west half is magenta over the floor, the free south-east quarter leaves the
    # floor as it was, and the north-east quarter is cyan (so the grid is not drawn upside down).
    lethal_on, free_on = pixel(page, s, 10.5, 11.0), pixel(page, s, 11.5, 10.5)
    assert lethal_on[0] - lethal_on[1] > 80 and lethal_on[2] - lethal_on[1] > 80, lethal_on
    inscribed = pixel(page, s, 11.5, 11.5)
    assert inscribed[1] - inscribed[0] > 80 and inscribed[2] - inscribed[0] > 80, inscribed
    # Marker: a green sphere of 1 m at (26, 17).
    assert pixel(page, s, 26.0, 17.0) == MARKER_RGB
    # Footprint: its outline passes through (15, 8), the middle of its west side.
    sx, sy = screen(s, 15.0, 8.0)
    assert canvas_rgb(page, math.floor(sx), math.floor(sy)) == FOOTPRINT_RGB
    # Recent path: the robot's own track along x = 20, from the pose history.
    assert layers["trail"] >= 5
    sx, sy = screen(s, 20.0, 3.0)
    assert canvas_rgb(page, math.floor(sx), math.floor(sy)) == PATH_RGB
    # The page names each layer's topic.
    assert "/scan" in page.locator('[data-layer-row="scan"]').inner_text()
    assert "/global_costmap/costmap" in page.locator('[data-layer-row="costmap"]').inner_text()

    # Each checkbox hides its layer.
    toggle(page, "scan", False)
    assert pixel(page, s, 25.0, 8.0) != SCAN_RGB
    toggle(page, "costmap", False)
    lethal_off = pixel(page, s, 10.5, 11.0)
    assert lethal_off != lethal_on and pixel(page, s, 11.5, 10.5) == free_on
    assert pixel(page, s, 11.5, 11.5) != inscribed
    toggle(page, "markers", False)
    assert pixel(page, s, 26.0, 17.0) != MARKER_RGB
    toggle(page, "footprint", False)
    assert canvas_rgb(page, math.floor(screen(s, 15.0, 8.0)[0]), math.floor(screen(s, 15.0, 8.0)[1])) != FOOTPRINT_RGB
    toggle(page, "path", False)
    assert canvas_rgb(page, math.floor(screen(s, 20.0, 3.0)[0]), math.floor(screen(s, 20.0, 3.0)[1])) != PATH_RGB

    # Remembered in this browser: after a reload the scan is still hidden, until switched back on.
    page.goto(f"{live_server.url}/livemap/{B}")
    page.wait_for_function("window.liveMapState && window.liveMapState.layers && window.liveMapState.imageLoaded")
    assert page.locator('input[data-layer="scan"]').is_checked() is False
    assert state(page)["layers"]["shown"]["scan"] is False
    toggle(page, "scan", True)
    s = feed_until_drawn(page, sensing)
    assert pixel(page, s, 25.0, 8.0) == SCAN_RGB
    # Costmap opacity is a setting of the page too: fully opaque, the lethal cell is pure magenta.
    toggle(page, "costmap", True)
    page.locator("#overlay-costmap-opacity").fill("100")
    page.wait_for_function("window.liveMapState.layers.opacity === 1")
    page.wait_for_timeout(100)
    assert pixel(page, s, 10.5, 11.0) == (255, 0, 255)
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_skipped_messages_are_counted_on_the_page(live_server, page, sensing):
    open_map(page, live_server.url)
    sensing.wait_match("/scan")
    bad = {**scan_msg(), "ranges": []}
    deadline = time.monotonic() + 15
    while "skipped" not in page.locator("#overlay-skipped-scan").inner_text():
        assert time.monotonic() < deadline, "the page never showed the skipped scan"
        sensing.publish("/scan", bad)
        page.wait_for_timeout(500)
    assert "empty" in page.locator("#overlay-skipped-scan").get_attribute("title")


def test_a_page_opened_later_reads_a_costmap_the_channel_no_longer_carries(live_server, page, sensing):
    """The channel carries only the grids that changed: once the local costmap has changed since
    the global one, a new page's snapshot has the global one without its cells, and the page reads
    them from the API."""
    sensing.advertise("/local_costmap/costmap", GRID, qos="latched")
    sensing.wait_match("/global_costmap/costmap")
    sensing.wait_match("/local_costmap/costmap")
    sensing.publish("/global_costmap/costmap", grid_msg())
    local = {**grid_msg(), "info": {**grid_msg()["info"], "origin": {"position": {"x": 14.0, "y": 10.0},
                                                                   "orientation": {"w": 1.0}}}}
    deadline = time.monotonic() + 20
    while True:   # until the latest `costmap` value is the local one's, the global one without its cells
        sensing.publish("/local_costmap/costmap", local)
        time.sleep(1.2)
        latest = live_server.rover.hub.latest("costmap")
        if latest and len(latest["costmaps"]) == 2 and latest["costmaps"][0]["data"] is None:
            break
        assert time.monotonic() < deadline, latest
    open_map(page, live_server.url)
    page.wait_for_function("window.liveMapState.layers.costmaps.length === 2", timeout=15000)
    s = state(page)
    lethal = pixel(page, s, 10.5, 11.0)    # the global grid's lethal west half, drawn from the API's cells
    assert lethal[0] - lethal[1] > 80 and lethal[2] - lethal[1] > 80, lethal
    assert page.watch.console_errors == []
