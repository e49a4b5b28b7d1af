"""The replay view's LiveMap, plots, diagnostics and camera in Chromium, over a recording with known
content at known times (tests/support/mcap_files.py), checked by pixels and by what the page shows
at known slider positions; and while it plays, nothing reaches the robot (a peer listening on the
recorded topics hears nothing) and the page sends nothing but GETs. Also the upload from the page."""

from __future__ import annotations

import pytest
import requests
from playwright.sync_api import expect

from rover_web.livemap.geometry import MapGeometry
from tests.support.mcap_files import T0, pose_x, upload, write_run

pytestmark = [pytest.mark.browser, pytest.mark.ros]
WAIT_MS = 15000
SPAN_S = 9.95  # the run's first to last message
ROBOT = (0x1F, 0x6F, 0xEB)  # livemap/draw.js COLORS.robot
LISTENED = {"/amcl_pose": "geometry_msgs/msg/PoseWithCovarianceStamped", "/odom": "nav_msgs/msg/Odometry",
            "/camera/image_raw": "sensor_msgs/msg/Image", "/diagnostics": "diagnostic_msgs/msg/DiagnosticArray",
            "/fix": "sensor_msgs/msg/NavSatFix", "/rover_web/audit": "std_msgs/msg/String"}

PIXEL = """([selector, x, y]) => {
    const el = document.querySelector(selector);
    let source = el;
    if (el.tagName === 'IMG') {  // an image: drawn into a canvas of its own to read it
        source = document.createElement('canvas');
        source.width = el.naturalWidth; source.height = el.naturalHeight;
        source.getContext('2d').drawImage(el, 0, 0);
    }
    return Array.from(source.getContext('2d').getImageData(Math.round(x), Math.round(y), 1, 1).data).slice(0, 3);
}"""


def near(rgb, expected, tolerance=12) -> bool:
    return all(abs(a - b) <= tolerance for a, b in zip(rgb, expected, strict=True))


def slide_to(page, seconds: float) -> float:
    """The slider at the step nearest `seconds` after the start (1,000 steps over the run); the time shown."""
    value = round(seconds / SPAN_S * 1000)
    page.locator("#replay-slider").fill(str(value))
    return T0 + value / 1000 * SPAN_S


@pytest.fixture
def replay(live_server, ros_peer, page, tmp_path):
    answer = upload(live_server, write_run(tmp_path / "run.mcap"), name="known run")
    assert answer.status_code == 201, answer.text
    peer = ros_peer("replay_listener")
    for topic, type_name in LISTENED.items():
        peer.subscribe(topic, type_name)
    sent = []
    page.on("request", lambda r: r.method != "GET" and sent.append(f"{r.method} {r.url}"))
    page.goto(f"{live_server.url}/recordings/{answer.json()['id']}/replay", wait_until="load")
    page.wait_for_selector("#replay-livemap[data-ready='yes']", timeout=WAIT_MS)
    yield page
    assert sent == [], sent
    assert {topic: len(peer.received(topic)) for topic in LISTENED} == dict.fromkeys(LISTENED, 0)
    assert page.watch.console_errors == [] and page.watch.offhost == []


def test_livemap_draws_the_recorded_pose_where_the_livemap_page_would(replay):
    page = replay
    for s, shown_x in ((4.1, pose_x(4.0)), (7.52, pose_x(7.5))):
        t = slide_to(page, s)
        page.wait_for_function("t => window.replayLiveMap && window.replayLiveMap.t === t", arg=t, timeout=WAIT_MS)
        state = page.evaluate("window.replayLiveMap")
        assert (state["pose"]["x"], state["pose"]["y"]) == (pytest.approx(shown_x), 2.0)
        expect(page.locator("#replay-livemap-robot")).to_have_text(f"{shown_x:.2f}, 2.00 m · 29°")
        # The same pixel as the server's map geometry and the page's view put it.
        g = state["geometry"]
        px, py = MapGeometry(g["w"], g["h"], g["res"], g["ox"], g["oy"], g["oyaw"]).world_to_pixel(shown_x, 2.0)
        view = state["view"]
        sx, sy = view["ox"] + px * view["scale"], view["oy"] + py * view["scale"]
        assert (state["pose"]["screen"]["x"], state["pose"]["screen"]["y"]) == (pytest.approx(sx), pytest.approx(sy))
        # Just off the heading line (it points east-north-east): the robot's blue.
        dpr = state["dpr"]
        assert near(page.evaluate(PIXEL, ["#replay-livemap-canvas", (sx - 1.5) * dpr, (sy + 1.5) * dpr]), ROBOT)
    expect(page.locator("#replay-livemap-pose option").first).to_have_text("/amcl_pose")


def test_plots_draw_a_recorded_field_and_its_value_at_the_slider(replay):
    page = replay
    page.select_option("#replay-plot-topic", "/odom")
    page.wait_for_selector("#replay-plot-fields option[value='pose.pose.position.x']", state="attached",
                           timeout=WAIT_MS)
    page.fill("#replay-plot-field", "pose.pose.position.x")
    page.click("#replay-plot-add")
    expect(page.locator("#replay-plot-chart")).to_have_attribute("data-points", "200", timeout=WAIT_MS)
    expect(page.locator("#replay-plot-chart canvas")).to_have_count(1)
    value = page.locator("#replay-plot-values li[data-series='/odom pose.pose.position.x']")
    slide_to(page, 4.1)
    expect(value).to_have_text("/odom pose.pose.position.x = 4.05")
    slide_to(page, 7.52)
    expect(value).to_have_text("/odom pose.pose.position.x = 7.5")
    page.fill("#replay-plot-field", "pose..x")
    page.click("#replay-plot-add")
    expect(page.locator("#replay-plot-error")).to_contain_text("field must be a path")
    # Chromium logs that 400 itself; it is the refusal asked for, not a fault of the page.
    page.watch.console_errors[:] = [e for e in page.watch.console_errors if "status of 400" not in e]


def test_diagnostics_show_the_board_at_the_sliders_time(replay):
    page = replay
    rows = page.locator("#replay-diag-body tr")
    slide_to(page, 4.1)
    expect(rows.filter(has_text="motor")).to_have_attribute("data-level", "OK", timeout=WAIT_MS)
    expect(rows.filter(has_text="battery")).to_contain_text("low")
    expect(rows.filter(has_text="gps")).to_have_attribute("data-level", "OK")
    slide_to(page, 7.52)
    expect(rows.filter(has_text="motor")).to_have_attribute("data-level", "ERROR", timeout=WAIT_MS)
    expect(rows.filter(has_text="motor")).to_contain_text("overheat")
    expect(rows.filter(has_text="motor")).to_contain_text("temp: 47")
    expect(rows.filter(has_text="gps")).to_have_attribute("data-level", "STALE")  # heard at 2 s only
    slide_to(page, 0)
    expect(rows).to_have_count(2)  # gps is not heard of yet


def test_the_camera_shows_the_frame_recorded_at_the_sliders_time(replay):
    page = replay
    frame = page.locator("#replay-frame")
    for s, logged, colour in ((4.1, 4.0, (255, 0, 0)), (7.52, 7.5, (0, 0, 255))):
        slide_to(page, s)
        expect(frame).to_have_attribute("data-frame-time", f"{T0 + logged:.3f}", timeout=WAIT_MS)
        page.wait_for_function("() => document.querySelector('#replay-frame').complete")
        assert near(page.evaluate(PIXEL, ["#replay-frame", 32, 24]), colour)
    expect(page.locator("#replay-frame-note")).to_contain_text("s before the slider")


def test_playing_moves_every_part_and_sends_nothing(replay):
    page = replay
    slide_to(page, 0)
    page.select_option("#replay-speed", "10")
    page.click("#replay-play")
    expect(page.locator("#replay-play")).to_have_text("Play", timeout=WAIT_MS)  # played to the end at 10x
    expect(page.locator("#replay-livemap-robot")).to_have_text(f"{pose_x(9.9):.2f}, 2.00 m · 29°")
    expect(page.locator("#replay-frame")).to_have_attribute("data-frame-time", f"{T0 + 9.5:.3f}", timeout=WAIT_MS)
    expect(page.locator("#replay-audit")).to_contain_text("carol")


def test_an_operator_uploads_a_file_from_the_page_and_a_bad_one_is_refused(live_server_factory, page, tmp_path):
    live_server = live_server_factory(ROVER_WEB_RECORDING_UPLOAD_MAX_MB=0.06)  # the run is ~45 KB
    good = write_run(tmp_path / "field run.mcap")
    longer = write_run(tmp_path / "longer.mcap", seconds=20)
    bad = tmp_path / "notes.mcap"
    bad.write_bytes(b"not an mcap file at all")
    page.goto(live_server.url + "/recordings", wait_until="load")
    page.set_input_files("#rec-upload-file", str(longer))
    page.click("#rec-upload")
    expect(page.locator("#rec-upload-status")).to_contain_text("over ROVER_WEB_RECORDING_UPLOAD_MAX_MB (0.06 MB)")
    page.set_input_files("#rec-upload-file", str(bad))
    page.click("#rec-upload")
    expect(page.locator("#rec-upload-status")).to_contain_text("Not uploaded: this is not an MCAP file",
                                                               timeout=WAIT_MS)
    page.set_input_files("#rec-upload-file", str(good))
    page.click("#rec-upload")
    expect(page.locator("#rec-upload-status")).to_have_text("field run uploaded: 382 messages, 10 s.",
                                                            timeout=WAIT_MS)
    row = page.locator("#rec-rows tr[data-source='uploaded']")
    expect(row).to_contain_text("field run", timeout=WAIT_MS)
    expect(row).to_contain_text("uploaded by 127.0.0.1")
    expect(row.locator("a", has_text="replay")).to_be_visible()
    listed = requests.get(live_server.url + "/api/recordings", timeout=5).json()["recordings"]
    assert [(r["name"], r["source"]) for r in listed] == [("field run", "uploaded")]
    # Chromium logs the refused upload's 422 itself; nothing else went wrong.
    assert [e for e in page.watch.console_errors if "422" not in e] == [] and page.watch.offhost == []


def test_the_replay_page_keeps_the_content_security_policy(live_server, browser, tmp_path):
    from tests.browser.test_csp import RECORD_VIOLATIONS
    from tests.conftest import PageWatch

    made = upload(live_server, write_run(tmp_path / "run.mcap")).json()
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # bypass_csp stays off
    context.add_init_script(RECORD_VIOLATIONS)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        page.goto(f"{live_server.url}/recordings/{made['id']}/replay")
        page.wait_for_selector("#replay-livemap[data-ready='yes']", timeout=WAIT_MS)
        page.select_option("#replay-plot-topic", "/odom")
        page.wait_for_selector("#replay-plot-fields option", state="attached", timeout=WAIT_MS)
        page.fill("#replay-plot-field", "pose.pose.position.x")
        page.click("#replay-plot-add")
        page.wait_for_selector("#replay-plot-chart canvas", timeout=WAIT_MS)
        slide_to(page, 5)
        page.wait_for_selector("#replay-frame[data-frame-time]:not([data-frame-time=''])", timeout=WAIT_MS)
        page.wait_for_selector(".maplibregl-canvas", timeout=WAIT_MS)
        page.wait_for_load_state("networkidle")
        assert page.evaluate("window.__csp") == []
        assert watch.console_errors == [] and watch.offhost == []
    finally:
        context.close()
