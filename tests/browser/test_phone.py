"""Every page on a 390 px phone, with the simulator publishing (long topic names, full tables), for
one robot and for three: no page scrolls sideways, and LiveMap's waypoint names stay inside the map."""

import pytest

pytestmark = pytest.mark.browser

PHONE = {"width": 390, "height": 844}
# Each page with what shows its content has arrived (the long rows that used to push the page wide).
PAGES = {
    "/": ["#teleop-link[data-state='live']"],
    "/status": ["#status-topics tr"],
    "/livemap": [".maplibregl-canvas, #livemap canvas, canvas"],
    "/topics": ["#topic-rows tr, table tbody tr"],
    "/panels": [],
    "/waypoints": [],
    "/logs": [],
    "/diagnostics": ["table tbody tr"],
    "/ros": [],
    "/robots": ["table tbody tr"],
    "/recordings": [],
    "/plot": [],
    "/plot?topic=/odom&field=twist.twist.linear.x": ["#plot-chart canvas"],
    "/api/docs": [".swagger-ui .info"],
}

# The elements that end past the screen's right edge, deepest first (what to fix), for the message.
WIDE = """() => {
    const out = [];
    for (const el of document.querySelectorAll('body *')) {
        const r = el.getBoundingClientRect();
        if (r.right > 390.5 && el.checkVisibility()) {
            if (![...el.children].some(c => c.getBoundingClientRect().right > 390.5))
                out.push(`${el.tagName.toLowerCase()}#${el.id}.${el.className} right=${Math.round(r.right)}`);
        }
    }
    return out.slice(0, 8);
}"""


def overflow(page) -> int:
    # Against the phone's width, not innerWidth: a mobile browser widens its layout viewport to a
    # page that overflows, and innerWidth then grows with it.
    return page.evaluate("document.documentElement.scrollWidth") - PHONE["width"]


def wide_pages(browser, base_url, pages, language=None):
    context = browser.new_context(viewport=PHONE, is_mobile=True, has_touch=True, bypass_csp=True)
    if language:
        context.add_cookies([{"name": "rover_web_lang", "value": language, "url": base_url}])
    try:
        page = context.new_page()
        wide = {}
        for path, shown in pages.items():
            page.goto(base_url + path)
            for selector in shown:
                page.wait_for_selector(selector, timeout=15000)
            page.wait_for_timeout(800)  # live rows and charts fill in (each page waited above for its own)
            if overflow(page) > 0:
                wide[path] = (overflow(page), page.evaluate(WIDE))
        return "\n".join(f"{path}: {px}px wider: {els}" for path, (px, els) in wide.items())
    finally:
        context.close()


def test_no_page_scrolls_sideways_on_a_phone(live_server, browser, sim_process):
    sim_process()
    assert wide_pages(browser, live_server.url, PAGES) == ""


# The pages with the most controls and labels; Spanish's words are the longest of the three languages,
# Japanese's the widest glyphs (scripts/bootstrap.sh installs a Japanese font, so they are drawn).
WORDY = ["/", "/status", "/livemap", "/panels", "/waypoints", "/ros", "/recordings", "/tf", "/3d"]


@pytest.mark.parametrize("language", ["es", "ja"])
def test_no_page_scrolls_sideways_on_a_phone_in_spanish_or_japanese(live_server, browser, sim_process, language):
    sim_process()
    pages = {path: PAGES.get(path, []) for path in WORDY}
    assert wide_pages(browser, live_server.url, pages, language) == ""


def test_no_fleet_page_scrolls_sideways_on_a_phone(live_server_factory, browser, sim_process):
    """Several robots: the fleet table, namespaced topic names, the selector and "Stop all"."""
    server = live_server_factory(ROVER_WEB_ROBOTS=[{"name": "boat", "kind": "boat"}, {"name": "rover", "kind": "rover"},
                                                   {"name": "drone", "kind": "drone"}])
    sim_process("--robots", "boat:boat,rover:rover,drone:drone")
    pages = {"/robots": ["#fleet-table tbody tr"], "/robots/rover/topics": ["table tbody tr"],
             "/robots/drone/": ["#link-server[data-state='live']"], "/robots/boat/status": ["#status-topics tr"],
             "/robots/rover/diagnostics": [], "/robots/boat/ros": [], "/robots/drone/panels": []}
    assert wide_pages(browser, server.url, pages) == ""


def test_livemap_labels_stay_inside_the_map_on_a_phone(live_server, browser):
    """Every waypoint whose marker is on the phone's map has its name drawn whole inside the map."""
    context = browser.new_context(viewport=PHONE, is_mobile=True, has_touch=True, bypass_csp=True)
    try:
        page = context.new_page()
        page.goto(live_server.url + "/livemap")
        page.wait_for_function("window.liveMapState && window.liveMapState.imageLoaded", timeout=15000)
        state = page.evaluate("window.liveMapState")
        width, height = state["canvas"]["width"], state["canvas"]["height"]
        on_map = [w for w in state["waypoints"] if 0 <= w["screen"]["x"] <= width and 0 <= w["screen"]["y"] <= height]
        assert on_map, "no waypoint on the phone's map: nothing was checked"
        near_edge = [w for w in on_map if w["screen"]["x"] + 8 + (w["label"]["right"] - w["label"]["left"]) > width]
        cut = [w["name"] for w in on_map if w["label"]["left"] < 0 or w["label"]["right"] > width
               or w["label"]["top"] < 0 or w["label"]["bottom"] > height]
        assert cut == []
        assert overflow(page) <= 0
        # Names near the right edge were the ones cut; the default view on a phone has some (the
        # basement's Boiler Room and Elevator), so the flip was exercised.
        assert near_edge
    finally:
        context.close()
