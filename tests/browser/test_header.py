"""The bar on top of every page in Chromium, at its most crowded: three robots (the selector and
"Stop all"), a signed-in user and an engaged e-stop. At a desktop's, a small laptop's and a phone's
width it stays one line, nothing in it leaves the screen, every page of the nav can be reached (in
the bar, or in the menu once opened), and the e-stop is in the bar and takes a click.
"""

import pytest
import requests

from tests.browser.test_auth import sign_in
from tests.support.auth import bearer

pytestmark = pytest.mark.browser

ROBOTS = [{"name": "boat"}, {"name": "drone"}, {"name": "rover"}]
SIZES = [(1400, 1000), (900, 900), (390, 844)]


@pytest.fixture
def crowded(signed_server_factory):
    server = signed_server_factory(ROVER_WEB_ROBOTS=ROBOTS)
    answer = requests.post(server.url + "/robots/drone/api/estop", json={"engaged": True},
                           headers=bearer(server, "operator"), timeout=5)
    assert answer.status_code == 200
    return server


def bar_layout(page):
    """How many rows the bar's items take, its height, and the items that end past the screen."""
    return page.locator("#topbar").evaluate("""bar => {
        const shown = [...bar.children].filter(c => c.getClientRects().length);
        const mids = shown.map(c => { const r = c.getBoundingClientRect(); return Math.round(r.top + r.height / 2); })
            .sort((a, b) => a - b);
        const rows = 1 + mids.slice(1).filter((m, i) => m - mids[i] > 8).length;
        const past = shown.filter(c => c.getBoundingClientRect().right > innerWidth + 0.5
                                       || c.getBoundingClientRect().left < -0.5).map(c => c.className);
        return { rows, height: bar.getBoundingClientRect().height, past,
                 scroll: document.documentElement.scrollWidth - innerWidth };
    }""")


# Shown whole: rendered, on screen, and not cut by an ancestor that clips or scrolls (the old bar
# scrolled its nav, and a link scrolled out of sight, or cut to "RO", is still "visible").
SHOWN_WHOLE = """as => as.filter(a => {
    if (!a.checkVisibility()) return false;
    const r = a.getBoundingClientRect();
    if (r.width < 1 || r.left < -0.5 || r.right > innerWidth + 0.5) return false;
    for (let p = a.parentElement; p && p !== document.body; p = p.parentElement) {
        if (getComputedStyle(p).overflowX === 'visible') continue;
        const c = p.getBoundingClientRect();
        if (r.left < c.left - 0.5 || r.right > c.right + 0.5) return false;
    }
    return true;
}).map(a => a.getAttribute('href'))"""


def reachable_links(page):
    """The nav's pages an operator can reach: shown in the bar, or shown in the menu once opened."""
    in_bar = page.locator("#topbar > .nav a").evaluate_all(SHOWN_WHOLE)
    if page.locator("#topbar-menu").is_visible():
        page.locator("#topbar-menu > summary").click()
        page.wait_for_selector("#topbar-menu[open]")
        in_menu = page.locator(".menu-nav a").evaluate_all(SHOWN_WHOLE)
        page.keyboard.press("Escape")
        page.wait_for_selector("#topbar-menu:not([open])")
    else:
        in_menu = []
    assert not set(in_bar) & set(in_menu), "a page is listed twice"
    return set(in_bar) | set(in_menu)


def takes_a_click(page, selector) -> bool:
    """The element is on screen and on top at its centre: a tap there lands on it."""
    return page.locator(selector).evaluate("""el => {
        const r = el.getBoundingClientRect();
        if (!r.width || r.left < 0 || r.right > innerWidth || r.top < 0 || r.bottom > innerHeight) return false;
        const hit = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
        return hit === el || el.contains(hit);
    }""")


@pytest.mark.parametrize("width,height", SIZES)
def test_the_crowded_bar_keeps_one_line_and_every_item_within_reach(crowded, page, width, height):
    page.set_viewport_size({"width": width, "height": height})
    sign_in(page, crowded.url, "operator")
    page.goto(crowded.url + "/robots/drone/status")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    page.wait_for_selector("#estop[data-engaged='yes']")
    expected = {"/robots/drone" + href
                for _, href in crowded.rover.nav_links}
    assert len(expected) >= 10  # the whole app's nav: what made the bar overflow

    layout = bar_layout(page)
    assert layout["rows"] == 1, layout
    assert layout["past"] == [] and layout["scroll"] <= 0, layout
    if width <= 400:
        assert layout["height"] <= 56, layout  # one line above the content on a phone

    assert reachable_links(page) == expected
    assert takes_a_click(page, "#estop-engage")
    assert takes_a_click(page, "#estop-all-engage")
    assert takes_a_click(page, "#estop-release")  # in the banner under the bar
    for pill in ("#link-server", "#link-robot", "#link-errors"):
        assert page.locator(pill).is_visible()

    # The robot selector and the user are in the bar or in the menu.
    for selector in ("#robot-select", ".whoami button"):
        if not page.locator(selector).is_visible():
            page.locator("#topbar-menu > summary").click()
            assert page.locator(selector).is_visible(), selector
            page.keyboard.press("Escape")
    assert page.watch.console_errors == []


def test_the_bar_keeps_its_height_as_it_squeezes(crowded, page):
    """Narrower windows take more steps (menu, dots, tighter buttons), never another height: a bar
    that grew or shrank would move every card under it, the joystick under a finger among them."""
    sign_in(page, crowded.url, "operator")
    page.goto(crowded.url + "/robots/drone/logs")
    seen = {}
    for width in (1600, 1200, 1000, 800, 600, 480, 390, 360):
        page.set_viewport_size({"width": width, "height": 900})
        page.wait_for_timeout(100)  # the refit runs on the next frame
        seen[width] = (page.locator("#topbar").evaluate("b => b.getBoundingClientRect().height"),
                       int(page.locator("#topbar").get_attribute("data-steps")))
        layout = bar_layout(page)
        assert layout["rows"] == 1 and layout["past"] == [], (width, layout)
    assert len({height for height, _ in seen.values()}) == 1, seen
    assert len({steps for _, steps in seen.values()}) >= 4, seen  # the steps were taken


def test_the_menu_works_by_keyboard_and_goes_where_its_links_say(crowded, page):
    page.set_viewport_size({"width": 390, "height": 844})
    sign_in(page, crowded.url, "operator")
    summary = page.locator("#topbar-menu > summary")
    summary.focus()
    page.keyboard.press("Enter")
    page.wait_for_selector("#topbar-menu[open]")
    page.keyboard.press("Escape")
    page.wait_for_selector("#topbar-menu:not([open])")
    assert page.evaluate("document.activeElement.tagName") == "SUMMARY"
    page.keyboard.press("Enter")
    page.locator(".menu-nav a", has_text="Diagnostics").click()
    page.wait_for_url("**/diagnostics")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert page.locator(".menu-nav a[aria-current='page'], #topbar > .nav a[aria-current='page']").count() == 1


def test_a_wide_window_keeps_the_nav_in_the_bar(live_server, page):
    """One robot, nobody signed in, a desktop: nothing needs the menu, and it is not there."""
    page.set_viewport_size({"width": 1920, "height": 1000})
    page.goto(live_server.url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert page.locator("#topbar-menu").is_hidden()
    shown = page.locator("#topbar > .nav a").evaluate_all(SHOWN_WHOLE)
    assert len(shown) == len(live_server.rover.nav_links)
    assert bar_layout(page)["rows"] == 1
