"""The dashboard in a real Chromium: loads offline, link health follows the server."""

import pytest

pytestmark = pytest.mark.browser


def test_dashboard_loads_with_nothing_off_host_and_no_console_errors(live_server, page):
    page.goto(live_server.url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert page.locator("#status-node").inner_text() == "/rover_web"
    assert page.locator("#link-robot").get_attribute("data-state") in ("no_data", "stale", "ok", "degraded")
    page.wait_for_load_state("networkidle")
    assert page.watch.offhost == []
    assert page.watch.console_errors == []


def test_dashboard_fits_a_phone(live_server, browser):
    context = browser.new_context(viewport={"width": 375, "height": 740}, is_mobile=True, has_touch=True,
                                  bypass_csp=True)
    try:
        phone = context.new_page()
        phone.goto(live_server.url + "/")
        phone.wait_for_selector("#link-server[data-state='live']", timeout=10000)
        overflow = phone.evaluate("document.documentElement.scrollWidth - document.documentElement.clientWidth")
        assert overflow <= 0, f"page is {overflow}px wider than a phone screen"
    finally:
        context.close()


def test_link_health_goes_lost_when_the_server_stops_and_live_when_it_returns(server_process, page):
    first = server_process().start()
    page.goto(first.url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    first.stop()
    page.wait_for_selector("#link-server[data-state='reconnecting'], #link-server[data-state='lost']", timeout=5000)
    page.wait_for_selector("#link-server[data-state='lost']", timeout=10000)
    assert page.locator("#link-robot").get_attribute("data-state") == "unknown"
    server_process(port=first.port).start()
    page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    assert page.watch.offhost == []
