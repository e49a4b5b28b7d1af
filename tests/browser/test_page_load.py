"""The page on a slow link, in Chromium: the header's E-STOP engages with scripts off (a plain form),
the page says its scripts have not run, and a warm reload asks the server for no static file."""

import logging
import re

import pytest
import requests

pytestmark = pytest.mark.browser


def test_with_scripts_off_the_header_estop_engages_and_says_so(live_server, browser):
    assert requests.get(live_server.url + "/api/estop", timeout=5).json()["engaged"] is False
    context = browser.new_context(java_script_enabled=False)
    try:
        page = context.new_page()
        page.goto(live_server.url + "/waypoints")
        # Nothing ran: the notice says so plainly (after its moment's delay).
        notice = page.locator("#scripts-pending")
        notice.wait_for(state="visible", timeout=5000)
        assert "have not loaded" in notice.inner_text()
        page.locator("#estop-engage").click()
        page.wait_for_selector("#estop-engaged-page", timeout=10000)
        assert "E-STOP ENGAGED" in page.locator("#estop-engaged-page h1").inner_text()
        assert page.locator("#estop").get_attribute("data-engaged") == "yes"
        assert page.locator("#estop-engaged-back").get_attribute("href") == "/waypoints"
    finally:
        context.close()
    state = requests.get(live_server.url + "/api/estop", timeout=5).json()
    assert state["engaged"] is True and state["via"] == "form"
    # Motion is refused now, as after any engage.
    drive = requests.post(live_server.url + "/api/teleop", json={"command": "forward"}, timeout=5)
    assert drive.status_code == 409, drive.text


def test_the_form_estop_keeps_the_origin_rule(live_server):
    foreign = requests.post(live_server.url + "/estop", data={"back": "/"}, timeout=5,
                            headers={"Origin": "http://evil.example"})
    assert foreign.status_code == 403
    assert requests.get(live_server.url + "/api/estop", timeout=5).json()["engaged"] is False
    own = requests.post(live_server.url + "/estop", data={"back": "//evil.example/x"}, timeout=5,
                        headers={"Origin": live_server.url})
    assert own.status_code == 200 and 'href="/"' in own.text and "evil.example" not in own.text
    assert requests.get(live_server.url + "/api/estop", timeout=5).json()["engaged"] is True


def test_with_scripts_on_the_notice_goes_and_the_estop_does_not_post_the_form(live_server, page):
    asked = []
    page.on("request", lambda r: asked.append(r.url[len(live_server.url):]))
    page.goto(live_server.url + "/")
    page.wait_for_selector("body[data-link='up']", timeout=15000)
    # The page ran from its bundle (rover_web/web/bundles.py): one module file, one stylesheet of its own.
    modules = [u for u in asked if u.startswith("/static/js/")]
    assert len(modules) == 1 and re.fullmatch(r"/static/js/bundle/[0-9a-f]{12}\.js", modules[0]), modules
    assert [u for u in asked if u.startswith("/static/css/")] == [
        u for u in asked if re.fullmatch(r"/static/css/bundle/[0-9a-f]{12}\.css", u)], asked
    assert page.locator("#scripts-pending").count() == 0
    page.locator("#estop-engage").click()
    page.wait_for_selector("#estop[data-engaged='yes']", timeout=5000)
    assert page.url.rstrip("/") == live_server.url.rstrip("/")  # the module engaged; no form page
    assert page.locator("#estop-engaged-page").count() == 0


@pytest.mark.parametrize("path", ["/", "/waypoints", "/robots", "/plot?topic=/odom&field=twist.twist.linear.x"])
def test_a_warm_reload_asks_for_no_static_file(live_server, browser, caplog, path):
    context = browser.new_context()
    try:
        page = context.new_page()
        page.goto(live_server.url + path)
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        page.wait_for_load_state("networkidle")
        caplog.clear()
        with caplog.at_level(logging.INFO, logger="werkzeug"):
            page.reload()
            page.wait_for_selector("body[data-link='up']", timeout=15000)
            page.wait_for_load_state("networkidle")
        asked = [m for r in caplog.records if r.name == "werkzeug" for m in re.findall(r'"GET (\S+)', r.getMessage())]
        assert asked, "the server logged no request at all: the check would see nothing"
        assert [u for u in asked if "/static/" in u] == [], asked
    finally:
        context.close()


def test_with_scripts_off_the_drive_cards_thumb_estop_engages_too(live_server, browser):
    """The touch layout's second E-STOP, under the driving thumb, is the header form's own button:
    it works before any script runs (a slow link, a translated page waiting for its catalogue)."""
    context = browser.new_context(java_script_enabled=False, viewport={"width": 390, "height": 844}, has_touch=True)
    try:
        page = context.new_page()
        page.goto(live_server.url + "/")
        page.locator("#teleop-estop").click()
        page.wait_for_selector("#estop-engaged-page", timeout=10000)
    finally:
        context.close()
    state = requests.get(live_server.url + "/api/estop", timeout=5).json()
    assert state["engaged"] is True and state["via"] == "form"
