"""The recordings page in Chromium: an operator records a list of topics from a peer in another
process, sees it run, stops it, and downloads the MCAP file; a viewer sees the list and no start."""

import re

import pytest
import requests
from playwright.sync_api import expect

from tests.integration.recording.helpers import STRING, start, wait_listed

pytestmark = [pytest.mark.browser, pytest.mark.ros]
WAIT_MS = 15000


def test_an_operator_records_topics_sees_it_run_stops_it_and_downloads_it(live_server, ros_peer, page):
    peer = ros_peer("page_recorded_peer")
    peer.advertise("/page_rec/chatter", STRING)
    wait_listed(live_server, "/page_rec/chatter")
    page.goto(live_server.url + "/recordings", wait_until="load")
    expect(page.locator("#rec-status")).to_have_text("Not recording.", timeout=WAIT_MS)
    page.check('input[name="rec-topics"][value="list"]')
    page.fill("#rec-list", "/page_rec/chatter")
    page.fill("#rec-name", "from the page")
    page.click("#rec-start")
    expect(page.locator("#rec-status")).to_contain_text("Recording from the page", timeout=WAIT_MS)
    expect(page.locator("#rec-stop")).to_be_visible()
    peer.wait_match("/page_rec/chatter", 1)
    for i in range(5):
        peer.publish("/page_rec/chatter", {"data": f"seen {i}"})
    # 5 from the peer and the audit trail's "recording.start".
    expect(page.locator("#rec-status")).to_contain_text("6 messages", timeout=WAIT_MS)
    page.click("#rec-stop")
    expect(page.locator("#rec-status")).to_have_text("Not recording. from the page stopped.", timeout=WAIT_MS)
    row = page.locator("#rec-rows tr[data-state='stopped']")
    expect(row).to_have_count(1, timeout=WAIT_MS)
    expect(row.locator("td").nth(5)).to_have_text("7")  # and the trail's "recording.stop"
    href = row.locator("a[download]").get_attribute("href")
    expect(row.locator("a", has_text="replay")).to_have_attribute("href", re.compile(r"/replay$"))
    assert requests.get(live_server.url + href, timeout=10).content.startswith(b"\x89MCAP0\r\n")
    assert page.watch.console_errors == [] and page.watch.offhost == []
    # A refused start is said on the page: a topic nobody publishes (Chromium logs the 422 itself).
    page.check('input[name="rec-topics"][value="list"]')
    page.fill("#rec-list", "/nobody/here")
    page.click("#rec-start")
    expect(page.locator("#rec-error")).to_contain_text("/nobody/here", timeout=WAIT_MS)


def test_a_viewer_sees_the_list_with_downloads_but_cannot_start(signed_server, browser):
    from tests.support.auth import PASSWORD, bearer

    made = start(signed_server, {"topics": "all", "name": "seen by viewers"}, headers=bearer(signed_server, "operator"))
    requests.post(f"{signed_server.url}/api/recordings/{made['id']}/stop", json={},
                  headers=bearer(signed_server, "operator"), timeout=15)
    context = browser.new_context()
    page = context.new_page()
    try:
        page.goto(signed_server.url + "/login?next=/recordings")
        page.fill("input[name=username]", "viewer")
        page.fill("input[name=password]", PASSWORD)
        page.click("button[type=submit]")
        page.wait_for_url("**/recordings", wait_until="load")
        row = page.locator("#rec-rows tr[data-state='stopped']")
        expect(row).to_contain_text("seen by viewers", timeout=WAIT_MS)
        expect(row.locator("a[download]")).to_have_text("download")
        expect(row.locator("button")).to_have_count(0)  # deleting is an admin's
        expect(page.locator("#rec-start")).to_be_disabled()
    finally:
        context.close()


def test_the_replay_view_moves_through_the_recording_and_sends_nothing(live_server, ros_peer, page):
    from tests.integration.recording.test_timeline import record_a_short_run

    recording_id = record_a_short_run(live_server, ros_peer("replay_view_peer"))
    sent = []
    page.on("request", lambda r: r.method != "GET" and sent.append(f"{r.method} {r.url}"))
    page.goto(f"{live_server.url}/recordings/{recording_id}/replay", wait_until="load")
    expect(page.locator("#replay-track-name")).to_have_text("/tl/fix (GPS)", timeout=WAIT_MS)
    page.locator("#replay-slider").fill("0")
    expect(page.locator("#replay-audit")).not_to_contain_text("carol")
    page.locator("#replay-slider").fill("1000")  # the end: everything has happened
    expect(page.locator("#replay-audit")).to_contain_text("carol: e-stop engaged by carol")
    expect(page.locator("#replay-logs")).to_contain_text("[WARN] replay_view_peer: thruster two hot")
    expect(page.locator("#replay-position")).to_have_text("at 27.370400, -82.450400")
    # On the waypoints map (MapLibre, the app's own style): the red point is the last fix.
    page.wait_for_selector("#replay-map[data-ready='yes']", timeout=WAIT_MS)
    page.locator("#replay-slider").fill("999")
    page.locator("#replay-slider").fill("1000")
    here = page.evaluate("window.roverReplayMap.getSource('replay-here').serialize().data.features[0]"
                         ".geometry.coordinates")
    assert [round(c, 6) for c in here] == [-82.4504, 27.3704]
    page.locator("#replay-slider").fill("0")
    page.click("#replay-play")
    expect(page.locator("#replay-play")).to_have_text("Play", timeout=WAIT_MS)  # played to the end at 1x
    expect(page.locator("#replay-audit")).to_contain_text("carol")
    assert sent == [] and page.watch.console_errors == []
