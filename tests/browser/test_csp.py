"""Every page under the app's Content-Security-Policy, enforced (no bypass): nothing is refused.

The other browser tests bypass the policy, because Playwright's wait_for_function compiles code
in the page; this one only navigates and waits on selectors, so the policy applies in full. The
policy has no 'unsafe-inline' for scripts or styles: an inline style="..." attribute in a
template, or one written by a script as markup, is a violation here.
"""

import pytest
import requests

from tests.conftest import PageWatch

pytestmark = pytest.mark.browser

# Each page with what shows it is drawn (the parts that would need a style to be refused).
PAGES = {
    "/": ["#livemap-thumb", ".maplibregl-canvas", "#teleop-link[data-state='live']", "#link-plot canvas",
          "#scan-the-code .stc-box"],
    "/status": ["#link-plot canvas"],
    "/livemap": [],
    "/topics": [],
    "/panels": [],
    "/waypoints": [],
    "/logs": [],
    "/diagnostics": [],
    "/ros": [],
    "/robots": [],
    "/recordings": ["#rec-rows tr"],
    "/plot?topic=/odom&field=twist.twist.linear.x": ["#plot-chart canvas"],
}
OTHER_PAGES = {"/api/docs": ".swagger-ui .info", "/login": "form"}  # no event stream on these

# Collects every securitypolicyviolation event from the first script on (Playwright injects it
# through the browser's debugging protocol, which the page's policy does not govern).
RECORD_VIOLATIONS = """
window.__csp = [];
document.addEventListener('securitypolicyviolation', (e) =>
  window.__csp.push(`${e.violatedDirective} ${e.blockedURI} ${e.sourceFile}:${e.lineNumber} ${e.sample}`));
"""


def test_the_policy_allows_no_inline_script_or_style(live_server):
    nonces = []
    for _ in range(2):
        answer = requests.get(live_server.url + "/", timeout=5)
        policy = answer.headers["Content-Security-Policy"]
        directives = dict(d.strip().split(" ", 1) for d in policy.split(";"))
        # One inline script is allowed, by a nonce of this response only: the page's import map
        # (rover_web/web/assets.py). Every other script is a file of this server's.
        own, nonce = directives["script-src"].split(" ")
        assert own == "'self'" and nonce.startswith("'nonce-")
        nonces.append(nonce[len("'nonce-"):-1])
        assert answer.text.count(f'nonce="{nonces[-1]}"') == 1
        assert f'<script type="importmap" nonce="{nonces[-1]}">' in answer.text
        assert directives["style-src"] == "'self'"
        assert "unsafe" not in policy
    assert nonces[0] != nonces[1]
    # A file's own answer allows no inline script at all.
    static = requests.get(live_server.url + "/api/status", timeout=5).headers["Content-Security-Policy"]
    assert "script-src 'self';" in static


def test_no_page_breaks_the_content_security_policy(live_server, browser, sim_process):
    sim_process()
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # bypass_csp stays off
    context.add_init_script(RECORD_VIOLATIONS)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        violations = {}
        for path, shown in PAGES.items():
            page.goto(live_server.url + path)
            page.wait_for_selector("body[data-link='up']", timeout=15000)
            for selector in shown:
                page.wait_for_selector(selector, timeout=10000)
            page.wait_for_load_state("networkidle")
            violations[path] = page.evaluate("window.__csp")
        for path, selector in OTHER_PAGES.items():
            page.goto(live_server.url + path)
            page.wait_for_selector(selector, timeout=10000)
            page.wait_for_load_state("networkidle")
            violations[path] = page.evaluate("window.__csp")
        assert {path: v for path, v in violations.items() if v} == {}
        refused = [m for m in watch.console_errors if "Content Security Policy" in m or "Refused to" in m]
        assert refused == [], refused
        assert watch.console_errors == [], watch.console_errors
        assert watch.offhost == []
    finally:
        context.close()


def test_the_dashboard_places_what_the_template_no_longer_styles(live_server, browser):
    """The live-map thumbnail keeps its floorplan's shape with its style set from the script."""
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    try:
        page = context.new_page()
        page.goto(live_server.url + "/")
        page.wait_for_selector("body[data-link='up']", timeout=15000)
        thumb = page.locator("#livemap-thumb")
        width, height = int(thumb.get_attribute("data-width")), int(thumb.get_attribute("data-height"))
        assert page.evaluate("getComputedStyle(document.getElementById('livemap-thumb')).aspectRatio") \
            == f"{width} / {height}"
    finally:
        context.close()
