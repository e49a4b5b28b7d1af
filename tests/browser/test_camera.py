"""The camera panel and the topic page in a real Chromium, against the simulator in its own process."""

import time

import pytest

from rover_web.camera.service import CameraStreams

pytestmark = pytest.mark.browser
# These are MJPEG's tests; the card plays WebRTC when it can (tests/browser/test_webrtc.py).
MJPEG = "localStorage.setItem('rover_web.camera.transport', 'mjpeg')"


@pytest.fixture(autouse=True)
def _mjpeg(request):
    if "page" in request.fixturenames:
        request.getfixturevalue("page").context.add_init_script(MJPEG)


def image_loaded(page):
    return page.evaluate("() => { const i = document.getElementById('camera-image');"
                         " return i.complete && i.naturalWidth; }")


def wait_full_size(page):
    """Until the card shows a 640-wide frame (20 s), or fails with the card's message."""
    deadline = time.monotonic() + 20
    while image_loaded(page) != 640:
        assert time.monotonic() < deadline, page.locator("#camera-message").inner_text()
        page.wait_for_timeout(200)


def test_camera_panel_shows_moving_frames_from_the_simulator(live_server, sim_process, page):
    sim_process()
    page.goto(live_server.url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    wait_full_size(page)
    assert page.locator("#camera-topic").input_value() == "/camera/image_raw"
    image = page.locator("#camera-image")
    first = image.screenshot()
    page.wait_for_timeout(1000)
    second = image.screenshot()
    assert first != second  # the pattern moves and the frame counter changes
    assert page.locator("#camera-message").is_hidden()
    # No network-idle wait here: the card reads the stream with fetch and acknowledges what it
    # received with a POST per frame or so (acked_stream.js), so the page is idle only in the gaps
    # (CI once found none for 10 s). A dashboard with no camera stream still reaches it (test_dashboard.py).
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_camera_panel_without_a_camera_says_so_without_failed_requests(live_server, page):
    page.goto(live_server.url + "/")
    page.wait_for_selector("#camera-message:not([hidden])", timeout=10000)
    assert "no image topic /camera/image_raw" in page.locator("#camera-message").inner_text()
    page.wait_for_load_state("networkidle")
    assert page.watch.console_errors == [] and page.watch.offhost == []
    assert live_server.rover.feature(CameraStreams).viewers == 0


def test_hidden_tab_drops_the_stream(live_server, sim_process, page):
    sim_process()
    page.goto(live_server.url + "/")
    camera = live_server.rover.feature(CameraStreams)
    deadline = time.monotonic() + 20
    while camera.viewers != 1:
        assert time.monotonic() < deadline, page.locator("#camera-message").inner_text()
        page.wait_for_timeout(100)  # not time.sleep: requests wait for Playwright to route them
    page.evaluate("() => { Object.defineProperty(document, 'hidden', {value: true, configurable: true});"
                  " document.dispatchEvent(new Event('visibilitychange')); }")
    deadline = time.monotonic() + 10
    while camera.viewers != 0:
        assert time.monotonic() < deadline, "the hidden page kept its stream"
        page.wait_for_timeout(100)  # not time.sleep: requests wait for Playwright to route them


def test_topic_page_lists_the_simulators_topics_and_echoes_one(live_server, sim_process, page):
    sim_process()
    page.goto(live_server.url + "/topics")
    for name, type_name in (("/camera/image_raw", "sensor_msgs/msg/Image"), ("/odom", "nav_msgs/msg/Odometry"),
                            ("/fix", "sensor_msgs/msg/NavSatFix"), ("/amcl_pose",
                                                                    "geometry_msgs/msg/PoseWithCovarianceStamped")):
        row = page.locator(f"#topics-body tr[data-topic='{name}']")
        row.wait_for(timeout=15000)
        assert type_name in row.inner_text()
    page.locator("#topics-body a[data-topic='/odom']").click()
    page.wait_for_function("document.getElementById('echo-msg').textContent.includes('child_frame_id')",
                           timeout=15000)
    assert '"base_link"' in page.locator("#echo-msg").inner_text()
    page.wait_for_function("parseFloat(document.getElementById('echo-rate').textContent) > 30", timeout=15000)
    assert page.locator("#echo-type").inner_text() == "nav_msgs/msg/Odometry"
    assert "/topics?topic=%2Fodom" in page.url
    # Filtering narrows the list.
    page.fill("#topics-filter", "navsat")
    page.wait_for_function("document.querySelectorAll('#topics-body tr').length === 1")
    # An image topic offers its video stream.
    page.fill("#topics-filter", "")
    page.locator("#topics-body a[data-topic='/camera/image_raw']").click()
    page.wait_for_selector("#echo-stream:not([hidden])", timeout=15000)
    assert page.watch.offhost == [] and page.watch.console_errors == []


STATS = r"/^\d+(\.\d)? fps · \d+×\d+ · [\d,]+ kbit\/s/"  # grouped in thousands: 1,250 kbit/s


def test_camera_card_shows_fps_size_and_kbps_and_a_snapshot_mode_it_remembers(live_server, sim_process, page):
    sim_process()
    page.goto(live_server.url + "/")
    # The server's figures for this page's own stream (GET /api/camera/viewers?viewer=...).
    page.wait_for_function(f"{STATS}.test(document.getElementById('camera-stats').textContent)", timeout=30000)
    assert "640×480" in page.locator("#camera-stats").inner_text()
    camera = live_server.rover.feature(CameraStreams)
    [viewer] = camera.clients()
    assert viewer["viewer"].startswith("card-") and viewer["width"] == 640

    snapshots = []
    page.on("request", lambda request: "/snapshot?" in request.url and snapshots.append(request.url))
    page.select_option("#camera-mode", "snapshots")
    page.wait_for_function("document.getElementById('camera-image').src.startsWith('blob:')", timeout=15000)
    page.wait_for_function(f"{STATS}.test(document.getElementById('camera-stats').textContent)", timeout=15000)
    deadline = time.monotonic() + 10
    while camera.clients():  # the MJPEG stream is gone; only snapshots now
        assert time.monotonic() < deadline, "the stream stayed open in snapshot mode"
        page.wait_for_timeout(100)
    page.wait_for_timeout(2500)
    assert len(snapshots) >= 2 and all("width=640" in url for url in snapshots)
    assert page.evaluate("() => document.getElementById('camera-image').naturalWidth") == 640

    page.reload()  # remembered per browser
    page.wait_for_function("document.getElementById('camera-image').src.startsWith('blob:')", timeout=15000)
    assert page.locator("#camera-mode").input_value() == "snapshots"
    assert camera.clients() == []
    page.select_option("#camera-mode", "live")
    page.wait_for_selector("#camera-image[data-transport='mjpeg-acked']", timeout=15000)
    page.wait_for_function("document.getElementById('camera-image').src.startsWith('blob:')", timeout=15000)
    assert len(camera.clients()) == 1
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_the_live_mjpeg_view_reads_the_stream_itself_and_acknowledges_what_it_received(
        live_server, sim_process, page):
    sim_process()
    acks = []
    page.on("request", lambda r: r.method == "POST" and "/api/camera/viewers/" in r.url and acks.append(r.url))
    page.goto(live_server.url + "/")
    page.wait_for_selector("#camera-image[data-transport='mjpeg-acked']", timeout=20000)
    wait_full_size(page)
    image = page.locator("#camera-image")
    assert image.get_attribute("src").startswith("blob:")
    first = image.screenshot()
    camera = live_server.rover.feature(CameraStreams)

    def acked():
        viewers = camera.clients()
        return viewers[0]["acked_bytes"] if len(viewers) == 1 and viewers[0]["acked"] else 0

    seen = acked()
    deadline = time.monotonic() + 20
    while acked() <= max(seen, 100_000):  # the server counts the page's acks, and they keep coming
        assert time.monotonic() < deadline, f"the server saw acks up to {acked()} bytes"
        page.wait_for_timeout(200)
    assert image.screenshot() != first  # frames keep coming
    [viewer] = camera.clients()
    # The size it gets follows how fast the page acknowledges (a loaded machine is a slow page).
    assert viewer["viewer"].startswith("card-") and viewer["asked"]["width"] == 640
    assert acks and all(url.endswith("/ack") for url in acks)
    page.wait_for_function(f"{STATS}.test(document.getElementById('camera-stats').textContent)", timeout=15000)
    assert page.watch.offhost == [] and page.watch.console_errors == []


def test_a_very_slow_stream_suggests_snapshot_mode(live_server_factory, sim_process, page):
    server = live_server_factory(ROVER_WEB_CAMERA_VIEWER_MAX_KBPS=8)  # 1 kB/s: about a frame a second at best
    sim_process()
    page.goto(server.url + "/")
    page.wait_for_selector("#camera-suggest:not([hidden])", timeout=40000)
    page.locator("#camera-suggest button").click()
    page.wait_for_function("document.getElementById('camera-image').src.startsWith('blob:')", timeout=15000)
    assert page.locator("#camera-mode").input_value() == "snapshots"
    assert page.locator("#camera-suggest").is_hidden()
    assert page.watch.offhost == [] and page.watch.console_errors == []
