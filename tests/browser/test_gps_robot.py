"""The robot on the GPS map in Chromium, from real publishers in another process: fix quality,
the heading arrow (and its going stale), and the accuracy circle read off the rendered map."""

import io
import math

import numpy as np
import pytest
from PIL import Image

from tests.browser.test_waypoints_map import open_map, wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]

NAV_SAT_FIX = "sensor_msgs/msg/NavSatFix"
ODOMETRY = "nav_msgs/msg/Odometry"
IMU = "sensor_msgs/msg/Imu"
LAT, LNG = 27.3742443, -82.4500873
BACKGROUND = np.array([0x17, 0x21, 0x2b])


def fix(status, variance=4.0, lat=LAT, lng=LNG):
    return {"header": {"frame_id": "gps"}, "status": {"status": status, "service": 1},
            "latitude": lat, "longitude": lng, "altitude": 1.0, "position_covariance_type": 2,
            "position_covariance": [variance, 0, 0, 0, variance, 0, 0, 0, 9.0]}


def odom(yaw):
    return {"header": {"frame_id": "odom"},
            "pose": {"pose": {"orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}}}


def robot(page):
    return page.evaluate("""() => { const n = document.querySelector('.wp-robot');
        return n && {fix: n.dataset.fix, quality: n.dataset.quality, heading: n.dataset.heading,
                     bearing: n.dataset.bearing, transform: n.style.transform}; }""")


def publish_until(page, peer, topic, msg, predicate, what):
    def shown():
        peer.publish(topic, msg)
        page.wait_for_timeout(100)
        return predicate()
    wait_until(page, shown, timeout=15, what=what)


def map_pixels(page):
    return np.asarray(Image.open(io.BytesIO(page.locator("#wp-map").screenshot())).convert("RGB")).astype(int)


def test_quality_heading_and_accuracy_circle(live_server_factory, ros_peer, page, tmp_path):
    # No drawn basemap: the circle's blue is read against the plain background.
    server = live_server_factory(ROVER_WEB_GPS_HEADING_STALE_S=1.0, ROVER_WEB_MAP_GEOJSON_DIR=str(tmp_path / "none"))
    peer = ros_peer("gps_and_odom")
    peer.advertise("/fix", NAV_SAT_FIX)
    peer.advertise("/odom", ODOMETRY)
    peer.wait_match("/fix")
    open_map(page, server.url)
    # Centre the map on the fix at zoom 21 (about 0.066 m a pixel here) so the 2 m circle is ~30 px.
    page.evaluate("([lng, lat]) => window.roverWaypointsMap.jumpTo({center: [lng, lat], zoom: 21})", [LNG, LAT])
    publish_until(page, peer, "/fix", fix(2), lambda: (robot(page) or {}).get("quality") == "gbas", "a GBAS fix")
    assert page.locator("#wp-quality").inner_text() == "GBAS fix (DGPS/RTK)"
    assert page.locator("#wp-fix").inner_text().endswith("±2 m")

    centre = page.evaluate("([lng, lat]) => { const p = window.roverWaypointsMap.project([lng, lat]);"
                           " return [p.x, p.y]; }", [LNG, LAT])
    cx, cy = centre

    def white(dx, dy):
        return min(map_pixels(page)[int(round(cy + dy)), int(round(cx + dx))]) > 220

    # Heading: yaw 0 in an east-aligned frame is a bearing of 90 degrees: the white wedge points east.
    publish_until(page, peer, "/odom", odom(0.0), lambda: (robot(page) or {}).get("heading") == "yes", "a heading")
    assert robot(page)["bearing"] == "90" and "rotateZ(90deg)" in robot(page)["transform"]
    page.wait_for_timeout(100)
    assert white(19, 0) and not white(0, -19)
    publish_until(page, peer, "/odom", odom(math.pi / 2), lambda: robot(page)["bearing"] == "0", "north")
    assert page.locator("#wp-heading").inner_text() == "0°"
    page.wait_for_timeout(100)
    assert white(0, -19) and not white(19, 0)

    # The circle: the map's own projection says where the fix is; 2 m is one standard deviation.
    page.wait_for_timeout(300)
    metres_per_px = page.evaluate("""([lat]) => { const m = window.roverWaypointsMap;
        return 40075016.686 * Math.cos(lat * Math.PI / 180) / (512 * 2 ** m.getZoom()); }""", [LAT])
    radius_px = 2.0 / metres_per_px
    assert radius_px > 25
    shot = map_pixels(page)

    def tinted(dx, dy):
        patch = shot[int(round(cy + dy)) - 1:int(round(cy + dy)) + 2, int(round(cx + dx)) - 1:int(round(cx + dx)) + 2]
        pixel = np.median(patch.reshape(-1, 3), axis=0)
        return pixel[2] - BACKGROUND[2] > 20 and pixel[2] > pixel[0] + 25  # blue over the dark background
    assert tinted(-(radius_px * 0.8), 0) and tinted(0, radius_px * 0.8)      # inside, west and south of the dot
    assert not tinted(-(radius_px * 1.3), 0) and not tinted(0, radius_px * 1.3)  # outside the circle

    # A plain fix without augmentation, then lost lock: the dot greys and the circle goes.
    publish_until(page, peer, "/fix", fix(0), lambda: robot(page)["quality"] == "fix", "a plain fix")
    assert page.locator("#wp-quality").inner_text() == "GPS fix"
    publish_until(page, peer, "/fix", fix(-1), lambda: robot(page)["fix"] == "no", "no fix")
    assert page.locator("#wp-quality").inner_text() == "no fix"
    page.wait_for_timeout(300)
    shot = map_pixels(page)
    assert not tinted(-(radius_px * 0.8), 0)
    # The heading stops: after ROVER_WEB_GPS_HEADING_STALE_S it is no longer drawn.
    publish_until(page, peer, "/fix", fix(1), lambda: robot(page)["quality"] == "sbas", "an SBAS fix")
    wait_until(page, lambda: robot(page)["heading"] == "no", timeout=5, what="the heading going stale")
    assert page.locator("#wp-heading").get_attribute("data-stale") == "yes"
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_heading_from_an_imu_topic(live_server_factory, ros_peer, page):
    server = live_server_factory(ROVER_WEB_GPS_HEADING_TOPIC="/imu/data", ROVER_WEB_GPS_HEADING_TYPE="imu")
    peer = ros_peer("gps_and_imu")
    peer.advertise("/fix", NAV_SAT_FIX)
    peer.advertise("/imu/data", IMU, qos="sensor_data")
    open_map(page, server.url)
    publish_until(page, peer, "/fix", fix(0), lambda: robot(page) is not None, "a fix")
    yaw = math.radians(90 - 225)  # south-west
    imu = {"header": {"frame_id": "imu"}, "orientation": {"z": math.sin(yaw / 2), "w": math.cos(yaw / 2)}}
    publish_until(page, peer, "/imu/data", imu, lambda: robot(page)["bearing"] == "225", "an IMU heading")
    # An IMU that says it has no orientation (REP 145: covariance[0] = -1) is skipped, not drawn as east.
    no_orientation = {**imu, "orientation": {"w": 1.0}, "orientation_covariance": [-1.0] + [0.0] * 8}
    for _ in range(5):
        peer.publish("/imu/data", no_orientation)
        page.wait_for_timeout(100)
    assert robot(page)["bearing"] == "225"
    assert page.watch.offhost == [] and page.watch.console_errors == []
