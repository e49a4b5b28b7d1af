"""Every page under the app's Content-Security-Policy, enforced (no bypass): nothing is refused.

The other browser tests bypass the policy, because Playwright's wait_for_function compiles code
in the page; this one only navigates and waits on selectors, so the policy applies in full.
"""

import pytest

from tests.conftest import PageWatch

pytestmark = pytest.mark.browser

PAGES = ["/", "/status", "/livemap", "/topics", "/panels", "/waypoints", "/logs", "/diagnostics", "/ros",
         "/plot?topic=/odom&field=twist.twist.linear.x"]


def test_no_page_breaks_the_content_security_policy(live_server, browser, sim_process):
    sim_process()
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # bypass_csp stays off
    try:
        page = context.new_page()
        watch = PageWatch(page)
        for path in PAGES:
            page.goto(live_server.url + path)
            page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
            if path == "/":
                page.wait_for_selector(".maplibregl-canvas", timeout=10000)  # its worker comes from blob:
                page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
                page.wait_for_selector("#link-plot canvas", timeout=10000)  # uPlot draws under the policy
            if path == "/status":
                page.wait_for_selector("#link-plot canvas", timeout=10000)
            if path.startswith("/plot"):
                page.wait_for_selector("#plot-chart canvas", timeout=10000)
        refused = [m for m in watch.console_errors if "Content Security Policy" in m or "Refused to" in m]
        assert refused == [], refused
        assert watch.console_errors == [], watch.console_errors
        assert watch.offhost == []
    finally:
        context.close()
