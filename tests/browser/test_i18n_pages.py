"""The browser code's strings on the app's own pages, in Spanish and Japanese (issue 43): the page's
language comes from the rover_web_lang cookie, the server names the catalogue on <html data-catalogue>,
and what the modules write (the Drive card's link view, the link pills, the e-stop's state, the camera's
figures) is in that language, from the shipped translations/<lang>/LC_MESSAGES/browser.po."""

from __future__ import annotations

import re

import pytest
import requests
from babel.messages.pofile import read_po

from rover_web.config import ROOT

pytestmark = pytest.mark.browser


def translation(language: str, msgid: str) -> str:
    with (ROOT / "translations" / language / "LC_MESSAGES" / "browser.po").open("rb") as f:
        for m in read_po(f, locale=language):
            if m.id == msgid:
                return m.string
    raise KeyError(msgid)


def in_language(page, server, language: str):
    page.context.add_cookies([{"name": "rover_web_lang", "value": language, "url": server.url}])
    page.goto(server.url + "/")
    assert page.evaluate("document.documentElement.lang") == language
    url = page.evaluate("document.documentElement.dataset.catalogue")
    assert url, "a translated page names its catalogue"
    return url


@pytest.mark.parametrize("language", ["es", "ja"])
def test_the_dashboard_s_browser_strings_are_in_the_page_s_language(live_server, page, language):
    url = in_language(page, live_server, language)
    catalogue = requests.get(live_server.url + url, timeout=5).json()
    assert catalogue["messages"]["ENGAGED"] == translation(language, "ENGAGED")
    t = lambda msgid: translation(language, msgid)  # noqa: E731
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=15000)
    page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    assert page.locator("#link-server b").inner_text() == t("live")
    name = page.locator("#teleop-name").input_value()
    assert page.locator("#teleop-link").inner_text() == t("connected as %(name)s").replace("%(name)s", name)
    page.wait_for_selector("#teleop-linkq[data-quality='ok'], #teleop-linkq[data-quality='poor']", timeout=15000)
    quality = page.locator("#teleop-linkq").get_attribute("data-quality")
    assert page.locator("#teleop-quality").inner_text() == t(quality)
    page.wait_for_function("document.getElementById('teleop-rtt').textContent.endsWith(' ms')", timeout=10000)
    assert page.locator("#teleop-holder").inner_text() == t("free")

    page.locator("#estop-engage").click()
    page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=10000)
    try:
        assert page.locator("#estop-engage .estop-state").inner_text().strip() == t("ENGAGED")
        assert page.locator("#teleop-message").inner_text() == t("E-stop engaged: release it to drive.")
    finally:
        requests.post(live_server.url + "/api/estop", json={"engaged": False, "by": "test"}, timeout=5)
    assert page.watch.console_errors == []


def test_the_camera_figures_are_spanish_numbers(live_server_factory, sim_process, page):
    # MJPEG's figures (the server's, for this page's stream): no WebRTC session, whose line is its own.
    server = live_server_factory(ROVER_WEB_WEBRTC_MAX_VIEWERS=0)
    sim_process()
    in_language(page, server, "es")
    # Spanish groups thousands with a dot from five digits on, and its decimal sign is a comma.
    stats = r"/^\d+(,\d)? fps · \d+×\d+ · [\d.]+ kbit\/s/"
    try:
        page.wait_for_function(f"{stats}.test(document.getElementById('camera-stats').textContent)", timeout=45000)
    except Exception:
        pytest.fail(f"camera stats: {page.locator('#camera-stats').inner_text()!r}")
    assert "640×480" in page.locator("#camera-stats").inner_text()
    assert not re.search(r"\d\.\d fps", page.locator("#camera-stats").inner_text())


def test_an_english_page_names_no_catalogue_and_preloads_i18n_js(live_server, page):
    requests_made = []
    page.on("request", lambda r: requests_made.append(r.url))
    page.goto(live_server.url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    assert page.evaluate("document.documentElement.lang") == "en"
    assert page.evaluate("document.documentElement.hasAttribute('data-catalogue')") is False
    assert not [url for url in requests_made if url.endswith(".json")]
    # Every module imports it, so it comes with the page's first scripts: in the page's one bundle
    # (rover_web/web/bundles.py), or named up front when the page is served unbundled.
    bundles = page.eval_on_selector_all("script[type=module][src*='/js/bundle/']", "s => s.map((x) => x.src)")
    if bundles:
        code = requests.get(bundles[0], timeout=10).text
        source_map = re.search(r"//# sourceMappingURL=(\S+)", code).group(1)
        sources = requests.get(bundles[0].rsplit("/", 1)[0] + "/" + source_map, timeout=10).json()["sources"]
        assert any(s.endswith("core/i18n.js") for s in sources), sources
    else:
        preloads = page.eval_on_selector_all("link[rel=modulepreload]", "links => links.map((l) => l.href)")
        assert any("/static/js/core/i18n." in href for href in preloads), preloads
    assert page.locator("#link-server b").inner_text() == "live"
    assert page.watch.console_errors == []


@pytest.mark.parametrize("language", ["es", "ja"])
def test_the_recordings_page_says_its_state_in_the_page_s_language(live_server, page, language):
    in_language(page, live_server, language)
    page.goto(live_server.url + "/recordings")
    status = page.locator("#rec-status")
    status.wait_for(timeout=10000)
    page.wait_for_function("document.getElementById('rec-status').textContent !== ''", timeout=10000)
    assert status.inner_text() == translation(language, "Not recording.")
    assert page.locator("#rec-rows").inner_text().strip() == translation(language, "No recordings yet.")
    assert page.watch.console_errors == []
