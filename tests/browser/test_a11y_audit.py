"""The accessibility audit: axe-core (vendored, static/vendor/axe-core-4.14.1, injected by this test
only; no page loads it) on every page of the app, in both themes, at a desktop's and a phone's size:
no WCAG 2.0, 2.1 or 2.2 A/AA violation. One server, one page per theme: each page is loaded once and
audited at both sizes (docs/accessibility.md says how to run it alone).
"""

import json
import re

import pytest
import requests

pytestmark = pytest.mark.browser

AXE_URL = "/static/vendor/axe-core-4.14.1/axe.min.js"
TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa", "wcag22aa"]
SIZES = {"desktop": {"width": 1400, "height": 1000}, "phone": {"width": 390, "height": 844}}
THEMES = ["dark", "daylight"]
# Pages reached from no nav link; the nav's own come from the app's bar (below), so a new page is
# audited the day it is added to the nav.
EXTRA_PAGES = ["/status", "/plot?topic=/odom&field=twist.twist.linear.x"]
OTHER_PAGES = {"/api/docs": ".swagger-ui .info", "/login": "form"}  # no event stream on these
# What each page shows once drawn, so the audit sees the page an operator sees (as test_csp.py).
SHOWN = {"/": ["#teleop-link[data-state='live']", "#link-plot canvas"], "/status": ["#link-plot canvas"],
         "/plot?topic=/odom&field=twist.twist.linear.x": ["#plot-chart canvas"]}

RUN_AXE = """async (tags) => {
    const result = await axe.run(document, { runOnly: { type: 'tag', values: tags }, resultTypes: ['violations'] });
    return result.violations.map(v => ({ id: v.id, impact: v.impact,
        nodes: v.nodes.slice(0, 5).map(n => `${n.target.join(' ')}: ${n.failureSummary.split('\\n')[1] || ''}`) }));
}"""


def nav_pages(server_url) -> list[str]:
    html = requests.get(server_url + "/", timeout=5).text
    nav = html[html.index('<nav class="nav"'):]
    nav = nav[:nav.index("</nav>")]
    return re.findall(r'href="([^"]+)"', nav)


def audit(page, size):
    page.set_viewport_size(SIZES[size])
    page.wait_for_timeout(150)  # the bar fits itself on the next frame (static/js/header/fit.js)
    return page.evaluate(RUN_AXE, TAGS)


def test_every_page_in_both_themes_at_both_sizes_has_no_wcag_violation(live_server, browser, sim_process):
    sim_process()
    paths = list(dict.fromkeys(nav_pages(live_server.url) + EXTRA_PAGES))
    assert "/" in paths and "/livemap" in paths and len(paths) >= 12, paths
    found = {}
    audited = 0
    for theme in THEMES:
        context = browser.new_context(viewport=SIZES["desktop"])
        context.add_cookies([{"name": "rover_web_theme", "value": theme, "url": live_server.url}])
        try:
            page = context.new_page()
            for path in [*paths, *OTHER_PAGES]:
                page.goto(live_server.url + path)
                if path in OTHER_PAGES:
                    # Swagger UI parses a large bundle and the whole document: slow on a loaded machine.
                    page.wait_for_selector(OTHER_PAGES[path], timeout=30000)
                else:
                    page.wait_for_selector("body[data-link='up']", timeout=15000)
                    for selector in SHOWN.get(path, []):
                        page.wait_for_selector(selector, timeout=10000)
                page.wait_for_load_state("networkidle")
                assert page.evaluate("document.documentElement.dataset.theme") == theme
                assert page.evaluate("typeof window.axe") == "undefined"  # no page loads it itself
                page.add_script_tag(url=live_server.url + AXE_URL)
                for size in SIZES:
                    violations = audit(page, size)
                    audited += 1
                    if violations:
                        found[f"{path} {theme} {size}"] = violations
                page.set_viewport_size(SIZES["desktop"])
        finally:
            context.close()
    assert found == {}, json.dumps(found, indent=1)
    assert audited == len(THEMES) * len(SIZES) * (len(paths) + len(OTHER_PAGES))
