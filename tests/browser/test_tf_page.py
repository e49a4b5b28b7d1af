"""The TF page in Chromium, with the app's Content-Security-Policy enforced: a peer's tree drawn as
view_frames draws it (each frame under its parent), a frame's details on a click, the warnings, a
lookup through the form, a new frame appearing live, a refused lookup saying tf2's reason."""

import math
import time

import pytest

from rover_web.tf import TfService
from tests.conftest import PageWatch
from tests.integration.tf.test_tf_ros import TF, transform, yaw_q
from tests.support.waiting import wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]

RECORD_VIOLATIONS = """
window.__csp = [];
document.addEventListener('securitypolicyviolation', (e) => window.__csp.push(`${e.violatedDirective} ${e.sample}`));
"""


def test_the_tf_page_draws_the_tree_details_warnings_and_lookups(live_server, ros_peer, browser):
    peer = ros_peer("tf_page_peer")
    peer.advertise("/tf_static", TF, qos="latched")
    peer.publish("/tf_static", {"transforms": [transform("map", "odom", (1, 2, 0), (0, 0, 0, 1)),
                                               transform("base_link", "laser", (0.3, 0, 0.2), (0, 0, 0, 1)),
                                               transform("world", "gps_origin", (0, 0, 0), (0, 0, 0, 1))]})
    peer.advertise("/tf", TF, qos=100)
    peer.wait_match("/tf")
    wait_until(lambda: live_server.rover.feature(TfService).buffer.can_transform("map", "odom"), 10,
               "the static transforms")
    now = time.time()
    for i in range(5):
        peer.publish("/tf", {"transforms": [transform("odom", "base_link", (i, 0, 0), yaw_q(math.pi / 2),
                                                      now + i * 0.1)]})

    context = browser.new_context(viewport={"width": 1280, "height": 900})  # the policy enforced
    context.add_init_script(RECORD_VIOLATIONS)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        page.goto(live_server.url + "/tf")
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        # view_frames' shape: laser under base_link under odom under map; world a second root.
        page.wait_for_selector(".tf-frame[data-frame='map'][data-root='true'] ~ ul .tf-frame[data-frame='odom'] "
                               "~ ul .tf-frame[data-frame='base_link'] ~ ul .tf-frame[data-frame='laser']",
                               timeout=10000)
        assert page.get_attribute(".tf-frame[data-frame='laser']", "data-static") == "true"
        assert page.get_attribute(".tf-frame[data-frame='base_link']", "data-static") == "false"
        assert page.get_attribute(".tf-frame[data-frame='world']", "data-root") == "true"
        assert "unconnected trees" in page.inner_text("#tf-warnings")
        page.click(".tf-frame[data-frame='base_link']")
        page.wait_for_selector("#tf-details dd[data-field='parent']", timeout=5000)
        assert page.inner_text("#tf-details dd[data-field='parent']") == "odom"
        assert page.inner_text("#tf-details dd[data-field='kind']") == "dynamic"
        assert page.inner_text("#tf-details dd[data-field='rate']") == "10.0 Hz"
        # A lookup: the robot at odom (4, 0) facing +y; the laser 0.3 ahead of it, so at map (5, 2.3).
        page.fill("#tf-target", "map")
        page.fill("#tf-source", "laser")
        page.click(".tf-lookup button[type='submit']")
        page.wait_for_selector("#tf-lookup-result[data-error='false']", timeout=5000)
        assert "translation 5.000 2.300 0.200 m" in page.inner_text("#tf-lookup-result")
        assert "yaw 90.0°" in page.inner_text("#tf-lookup-result")
        page.fill("#tf-source", "camera")
        page.click(".tf-lookup button[type='submit']")
        page.wait_for_selector("#tf-lookup-result[data-error='true']", timeout=5000)
        assert page.inner_text("#tf-lookup-result").startswith('unknown_frame: "camera" passed to lookupTransform')
        # A new frame shows without a reload (the `tf` channel), and the details follow it.
        peer.publish("/tf_static", {"transforms": [transform("base_link", "camera", (0.1, 0, 0.5), (0, 0, 0, 1))]})
        page.wait_for_selector(".tf-frame[data-frame='base_link'] ~ ul .tf-frame[data-frame='camera']", timeout=10000)
        assert page.inner_text("#tf-details dd[data-field='children']") == "camera, laser"
        page.wait_for_load_state("networkidle")
        assert page.evaluate("window.__csp") == []
        # The one console error is the browser's own line about the refused lookup's 404.
        assert watch.console_errors == ["Failed to load resource: the server responded with a status of 404 "
                                        "(NOT FOUND)"]
        assert watch.offhost == []
    finally:
        context.close()


def test_the_tf_page_fits_a_phone(live_server, ros_peer, browser):
    from tests.browser.test_phone import wide_pages

    peer = ros_peer("tf_phone_peer")
    peer.advertise("/tf_static", TF, qos="latched")
    chain = [transform("map" if i == 0 else f"a_rather_long_frame_name_{i - 1}", f"a_rather_long_frame_name_{i}",
                       (0, 0, 0), (0, 0, 0, 1)) for i in range(8)]
    peer.publish("/tf_static", {"transforms": chain})
    wait_until(lambda: live_server.rover.feature(TfService).buffer.can_transform("map", "a_rather_long_frame_name_7"),
               10, "the chain")
    assert wide_pages(browser, live_server.url, {"/tf": [".tf-frame[data-frame='a_rather_long_frame_name_7']"]}) == ""


def test_a_recordings_frames_on_the_tf_page(live_server, browser, tmp_path):
    from tests.integration.tf.test_tf_replay import T0, write_tf_run
    from tests.support.mcap_files import upload

    answer = upload(live_server, write_tf_run(tmp_path / "tf.mcap"), name="tf run")
    assert answer.status_code == 201, answer.text
    rid = answer.json()["id"]
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # the policy enforced
    context.add_init_script(RECORD_VIOLATIONS)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        page.goto(f"{live_server.url}/recordings/{rid}/replay")
        page.wait_for_selector("#replay-tf[href*='?t=']", timeout=10000)  # follows the slider
        page.click("#replay-tf")
        page.wait_for_url(f"**/recordings/{rid}/tf?t={T0:.3f}")  # the slider starts at the beginning
        page.wait_for_selector(".tf-frame[data-frame='odom'] ~ ul .tf-frame[data-frame='base_link'] "
                               "~ ul .tf-frame[data-frame='laser']", timeout=10000)
        page.fill("input[name='t']", f"{T0 + 20:.3f}")
        page.click("form.tf-lookup:not(#tf-lookup) button[type='submit']")
        page.wait_for_url(f"**/recordings/{rid}/tf?t=*")
        page.wait_for_selector(".tf-frame[data-frame='laser']", timeout=10000)
        page.click(".tf-frame[data-frame='base_link']")
        assert page.inner_text("#tf-details dd[data-field='rate']") == "20.0 Hz"
        assert page.inner_text("#tf-details dd[data-field='newest stamp']") == f"{T0 + 20:.3f} s"
        # The lookup asks the recording (its URL already holds ?t=): at s = 12.5 the laser is at map (5, 12.7).
        page.fill("#tf-target", "map")
        page.fill("#tf-source", "laser")
        page.fill("#tf-time", f"{T0 + 12.5}")
        page.click("#tf-lookup button[type='submit']")
        page.wait_for_selector("#tf-lookup-result[data-error='false']", timeout=5000)
        assert "translation 5.000 12.700 0.100 m" in page.inner_text("#tf-lookup-result")
        assert page.evaluate("window.__csp") == []
        assert watch.console_errors == [] and watch.offhost == []
    finally:
        context.close()
