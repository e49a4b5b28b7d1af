"""The field: the daylight and dark themes, the touch layout, the keyboard and the screen reader, in
real Chromium (docs/accessibility.md).

- Legible: contrast ratios computed from the colours Chromium rendered, per theme: the e-stop (idle
  and engaged) and the status words at 7:1 or more in daylight, 4.5:1 in dark; the stick's knob
  against its card at 3:1 (a graphic).
- Touch: at a phone's 390 x 844 and a tablet's size, every control used while driving is 44 x 44 CSS
  px or more, none touches another, and the stick and the Drive card's E-STOP are on screen at once.
- Keyboard: Tab reaches the stick with a visible focus ring, W drives (a separate ROS process hears
  /cmd_vel), Space stops; the e-stop engages and releases by keyboard alone; the screen reader's
  live region says the e-stop once, and does not speak at the event rate.
- The theme chosen is kept per browser (a reload is rendered in it) and per user (a fresh browser
  that signs in gets the user's theme in the first byte).
"""

import time

import pytest
import requests

from tests.browser.test_auth import sign_in
from tests.support.auth import bearer
from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser

THEMES = ["dark", "daylight"]
TEXT_MINIMUM = {"dark": 4.5, "daylight": 7.0}
PHONE = {"width": 390, "height": 844}
TABLET = {"width": 820, "height": 1180}

# WCAG's contrast ratio of an element's text against what is painted behind it: the first ancestor
# (or itself) with an opaque background, semi-transparent ones blended over what is under them.
CONTRAST = """([el, which]) => {
    const rgba = (s) => { const m = s.match(/[\\d.]+/g).map(Number);
        return [m[0], m[1], m[2], m.length > 3 ? m[3] : 1]; };
    const over = (top, under) => [0, 1, 2].map(i => top[i] * top[3] + under[i] * (1 - top[3])).concat(1);
    function ground(node) {
        const layers = [];
        for (let n = node; n; n = n.parentElement) {
            const c = rgba(getComputedStyle(n).backgroundColor);
            if (c[3] > 0) layers.push(c);
            if (c[3] >= 1) break;
        }
        let colour = [255, 255, 255, 1];
        for (const c of layers.reverse()) colour = over(c, colour);
        return colour;
    }
    const lum = (c) => { const f = (v) => { v /= 255; return v <= 0.03928 ? v / 12.92 : ((v + 0.055) / 1.055) ** 2.4; };
        return 0.2126 * f(c[0]) + 0.7152 * f(c[1]) + 0.0722 * f(c[2]); };
    const style = getComputedStyle(el);
    const fg = which === 'background' ? ground(el) : over(rgba(style.color), ground(el));
    const bg = which === 'background' ? ground(el.parentElement.closest('.card') || document.body) : ground(el);
    const [a, b] = [lum(fg), lum(bg)].sort((x, y) => y - x);
    return Math.round(((a + 0.05) / (b + 0.05)) * 100) / 100;
}"""


def ratio(page, selector, which="text"):
    return page.locator(selector).first.evaluate(f"el => ({CONTRAST})([el, '{which}'])")


def themed_context(browser, url, theme, viewport=None, **options):
    context = browser.new_context(viewport=viewport or {"width": 1280, "height": 900}, **options)
    context.add_cookies([{"name": "rover_web_theme", "value": theme, "url": url}])
    return context


def open_dashboard(page, url):
    page.goto(url + "/")
    page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=15000)


@pytest.mark.parametrize("theme", THEMES)
def test_estop_stick_and_status_are_legible(live_server, browser, theme):
    context = themed_context(browser, live_server.url, theme)
    try:
        page = context.new_page()
        open_dashboard(page, live_server.url)
        assert page.evaluate("document.documentElement.dataset.theme") == theme
        ground = page.evaluate("getComputedStyle(document.body).backgroundColor")
        assert ground == ("rgb(238, 241, 244)" if theme == "daylight" else "rgb(15, 20, 25)")
        minimum = TEXT_MINIMUM[theme]
        measured = {name: ratio(page, selector) for name, selector in {
            "e-stop": "#estop-engage", "server": "#link-server b", "robot": "#link-robot b",
            "errors": "#link-errors b", "drive link": "#teleop-link"}.items()}
        # The stick's knob is a graphic: 3:1 against the card it sits on (WCAG 1.4.11).
        measured["stick"] = ratio(page, "#teleop-joystick .nipple .front", "background")
        page.locator("#estop-engage").click()
        page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=5000)
        measured["e-stop engaged"] = ratio(page, "#estop-engage")
        measured["banner"] = ratio(page, ".estop-banner-text b")
        measured["release"] = ratio(page, "#estop-release")
        print(theme, measured)  # the figures, with -s
        low = {k: v for k, v in measured.items() if v < (3.0 if k == "stick" else minimum)}
        assert low == {}, measured
    finally:
        context.close()
        requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5)


TOUCH_CONTROLS = ("#estop-engage, #teleop-estop, #teleop-joystick, #teleop-card button, #display-menu > summary, "
                  "#topbar-menu > summary, #topbar > .nav a, #estop-release")
# Each visible control's box, and the smallest gap between any two (0 when they touch or overlap).
BOXES = """els => {
    const shown = els.filter(e => e.checkVisibility()).map(e => ({ id: e.id || e.textContent.trim().slice(0, 20),
        r: e.getBoundingClientRect() }));
    const gaps = [];
    for (let i = 0; i < shown.length; i++) for (let j = i + 1; j < shown.length; j++) {
        const a = shown[i].r, b = shown[j].r;
        if (a.left <= b.left && a.right >= b.right && a.top <= b.top && a.bottom >= b.bottom) continue;  // nested
        if (b.left <= a.left && b.right >= a.right && b.top <= a.top && b.bottom >= a.bottom) continue;
        const dx = Math.max(0, b.left - a.right, a.left - b.right);
        const dy = Math.max(0, b.top - a.bottom, a.top - b.bottom);
        gaps.push([shown[i].id, shown[j].id, Math.max(dx, dy)]);
    }
    return { sizes: shown.map(s => [s.id, Math.round(s.r.width), Math.round(s.r.height)]), gaps };
}"""


@pytest.mark.parametrize("theme", THEMES)
def test_touch_targets_on_a_phone_and_a_tablet(live_server, browser, theme):
    requests.post(live_server.url + "/api/estop", json={"engaged": True}, timeout=5)  # Release shows
    for viewport in (PHONE, TABLET):
        context = themed_context(browser, live_server.url, theme, viewport=viewport, has_touch=True, is_mobile=True)
        try:
            page = context.new_page()
            page.goto(live_server.url + "/")
            page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
            page.wait_for_timeout(300)  # the bar fits itself (static/js/header/fit.js)
            boxes = page.locator(TOUCH_CONTROLS).evaluate_all(BOXES)
            ids = [s[0] for s in boxes["sizes"]]
            assert {"estop-engage", "teleop-estop", "teleop-joystick", "estop-release"} <= set(ids), ids
            small = [s for s in boxes["sizes"] if s[1] < 44 or s[2] < 44]
            assert small == [], (viewport, boxes["sizes"])
            touching = [g for g in boxes["gaps"] if g[2] < 4]
            assert touching == [], (viewport, touching)
            # The nav's pages in the menu, opened by a tap, are as large.
            if page.locator("#topbar-menu").is_visible():
                page.locator("#topbar-menu > summary").tap()
                links = page.locator(".menu-nav a").evaluate_all(BOXES)
                assert links["sizes"] and all(w >= 44 and h >= 44 for _, w, h in links["sizes"]), links["sizes"]
                page.locator("#topbar-menu > summary").tap()
            # Thumb reach: with the stick on screen, the Drive card's E-STOP is too, just under it.
            page.locator("#teleop-estop").scroll_into_view_if_needed()
            stick = page.locator("#teleop-joystick").bounding_box()
            estop = page.locator("#teleop-estop").bounding_box()
            assert 0 <= stick["y"] and estop["y"] + estop["height"] <= viewport["height"], (stick, estop)
            assert 0 <= estop["y"] - (stick["y"] + stick["height"]) <= 40
            # Nothing needs hover: a tap on the status dots (a phone's bar) shows their words.
            if page.locator("#topbar.squeeze-3").count():
                page.locator("#link-server").tap()
                words = page.locator("#link-words")
                words.wait_for(state="visible", timeout=2000)
                assert "Server:" in words.inner_text() and "Robot:" in words.inner_text()
        finally:
            context.close()
    requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5)


@pytest.fixture
def rig(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_TELEOP_DEADMAN_S=5.0, ROVER_WEB_WEBRTC_MAX_VIEWERS=0)
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    return server, peer


def tab_to(page, element_id, backwards=False, limit=150):
    for _ in range(limit):
        page.keyboard.press("Shift+Tab" if backwards else "Tab")
        if page.evaluate("document.activeElement && document.activeElement.id") == element_id:
            return
    raise AssertionError(f"#{element_id} not reached with the keyboard")


FOCUS_RING = """() => { const el = document.activeElement, s = getComputedStyle(el);
    return el.matches(':focus-visible') && s.outlineStyle !== 'none' ? parseFloat(s.outlineWidth) : 0; }"""


# Everything the screen reader's live region says, in order.
LISTEN = """() => { window.__said = []; const region = document.getElementById('a11y-announcer');
    new MutationObserver(() => window.__said.push(region.textContent))
        .observe(region, { childList: true, characterData: true, subtree: true }); }"""


@pytest.mark.parametrize("theme", THEMES)
def test_keyboard_alone_drives_stops_and_estops(rig, browser, theme):
    server, peer = rig
    context = themed_context(browser, server.url, theme, bypass_csp=True)  # for wait_for_function
    try:
        page = context.new_page()
        open_dashboard(page, server.url)
        page.evaluate(LISTEN)
        tab_to(page, "teleop-joystick")
        assert page.evaluate(FOCUS_RING) >= 2
        page.keyboard.down("w")
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
        time.sleep(0.3)
        peer.clear("/cmd_vel")
        t = time.monotonic()
        page.keyboard.press("Space")  # stops with W still held
        zero = peer.wait_for("/cmd_vel", is_zero, timeout=2)
        assert zero["t"] - t < 1.0
        time.sleep(0.4)
        assert all(lin == 0.0 and ang == 0.0 for ts, lin, ang in twists(peer) if ts >= zero["t"])
        page.keyboard.up("w")
        # The e-stop, from the stick, by keyboard: back to the bar's E-STOP, Enter.
        tab_to(page, "estop-engage", backwards=True)
        assert page.evaluate(FOCUS_RING) >= 2
        page.keyboard.press("Enter" if theme == "dark" else "Space")  # a button takes both keys
        page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=5000)
        assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is True
        page.wait_for_function("window.__said.some(s => s.includes('E-stop engaged'))", timeout=2000)
        # Release: Tab to Release, Enter opens the dialog on "Keep stopped"; Tab, Enter releases.
        tab_to(page, "estop-release")
        page.keyboard.press("Enter")
        page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
        assert page.evaluate("document.activeElement.id") == "estop-release-cancel"
        page.keyboard.press("Tab")
        assert page.evaluate("document.activeElement.id") == "estop-release-confirm"
        page.keyboard.press("Enter")
        page.wait_for_selector("#estop[data-engaged='no']", timeout=5000)
        # Not flooded: a few state changes said, never every event (the page had dozens by now).
        said = page.evaluate("window.__said")
        assert 1 <= len(said) <= 6, said
    finally:
        context.close()


def test_the_theme_is_kept_per_browser(live_server, browser):
    context = browser.new_context(viewport={"width": 1280, "height": 900})
    try:
        page = context.new_page()
        first = page.goto(live_server.url + "/")
        assert 'data-theme="auto"' in first.text()
        page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
        # By keyboard: Tab to the Display menu, open it, choose daylight.
        page.locator("#display-menu > summary").focus()
        page.keyboard.press("Enter")
        page.locator("#display-theme").select_option("daylight")
        assert page.evaluate("document.documentElement.dataset.theme") == "daylight"
        assert page.evaluate("getComputedStyle(document.body).backgroundColor") == "rgb(238, 241, 244)"
        cookie = {c["name"]: c for c in context.cookies()}["rover_web_theme"]
        assert cookie["value"] == "daylight" and cookie["path"] == "/" and cookie["sameSite"] == "Strict"
        assert cookie["expires"] - time.time() > 360 * 24 * 3600
        assert page.evaluate("localStorage.getItem('rover_web.theme')") == "daylight"
        again = page.reload()
        assert 'data-theme="daylight"' in again.text()  # rendered by the server, no flash
        assert page.locator("#display-theme").input_value() == "daylight"
        # A language change is kept the same way and renders the page again: chosen by keyboard,
        # once Enter says the choice is made (an arrow key alone changes the value at each press).
        page.evaluate("window.__before = true")  # gone if the page were rendered again
        page.locator("#display-menu > summary").click()
        page.locator("#display-language").focus()
        page.locator("#display-language").select_option("es")
        assert "Press Enter" in page.locator("#display-kept").inner_text()
        page.wait_for_timeout(300)
        assert page.evaluate("window.__before") is True
        with page.expect_navigation():
            page.keyboard.press("Enter")
        assert {c["name"]: c["value"] for c in context.cookies()}["rover_web_lang"] == "es"
        assert page.locator("#display-language").input_value() == "es"
        assert page.locator("#display-language option[value='ja']").text_content() == "日本語"
    finally:
        context.close()


def test_the_theme_follows_the_user_across_sign_in(signed_server, browser):
    first = browser.new_context()
    try:
        page = first.new_page()
        sign_in(page, signed_server.url, "operator")
        page.locator("#display-menu > summary").click()
        with page.expect_response(lambda r: r.url.endswith("/api/me/preferences") and r.request.method == "PUT") as put:
            page.locator("#display-theme").select_option("daylight")
        assert put.value.status == 200
    finally:
        first.close()
    saved = requests.get(signed_server.url + "/api/me/preferences", timeout=5,
                         headers=bearer(signed_server, "operator")).json()
    assert saved["saved"]["theme"] == "daylight"
    fresh = browser.new_context()  # no cookie, no storage: only the user can bring the theme
    try:
        page = fresh.new_page()
        sign_in(page, signed_server.url, "operator")
        assert "rover_web_theme" not in {c["name"] for c in fresh.cookies()}
        answer = page.goto(signed_server.url + "/livemap")
        assert 'data-theme="daylight"' in answer.text()
        assert page.locator("#display-theme").input_value() == "daylight"
        assert "Saved for operator" in page.locator("#display-kept").text_content()
    finally:
        fresh.close()
