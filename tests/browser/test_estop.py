"""The e-stop in Chromium: it stops a driving page, and a key held through the release does not
drive until it is released and pressed again; an engaged latch is unmistakable on every page, and
releasing it asks first."""

import time

import pytest
import requests

from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser


def release_estop(page):
    """Release from the banner, confirming in the page's dialog."""
    page.locator("#estop-release").click()
    page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
    page.locator("#estop-release-confirm").click()


def engaged_on_server(server) -> bool:
    return requests.get(server.url + "/api/estop", timeout=5).json()["engaged"]


def frame_of(page) -> dict:
    """The red frame an engaged latch draws around the window (body::after)."""
    return page.evaluate("""() => { const s = getComputedStyle(document.body, '::after');
        return { content: s.content, position: s.position, border: s.borderTopWidth, events: s.pointerEvents }; }""")


@pytest.mark.parametrize("width,height", [(1400, 1000), (390, 844)])
def test_an_engaged_estop_is_unmistakable_on_every_page_and_release_asks_first(live_server, page, width, height):
    page.set_viewport_size({"width": width, "height": height})
    requests.post(live_server.url + "/api/estop", json={"engaged": True, "by": "curl"}, timeout=5)
    for path in ("/logs", "/diagnostics", "/plot", "/topics", "/ros"):
        page.goto(live_server.url + path)
        banner = page.locator("#estop-banner")
        assert banner.is_visible(), path
        assert "E-STOP ENGAGED" in banner.inner_text() and "By curl" in banner.text_content()
        assert banner.bounding_box()["y"] < 120, path  # right under the bar, not down in the page
        frame = frame_of(page)
        assert frame["position"] == "fixed" and frame["border"] != "0px" and frame["events"] == "none", path
        assert page.locator("#estop-release").is_visible()

    # Escape, and "Keep stopped": the dialog closes and nothing was sent.
    posted = []
    page.on("request", lambda r: r.method == "POST" and posted.append(r.url))
    page.locator("#estop-release").click()
    dialog = page.locator("#estop-release-dialog")
    page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
    assert page.evaluate("document.activeElement.id") == "estop-release-cancel"  # the safe choice first
    page.keyboard.press("Escape")
    page.wait_for_selector("#estop-release-dialog", state="hidden", timeout=5000)
    page.locator("#estop-release").click()
    page.keyboard.press("Enter")  # on "Keep stopped"
    page.wait_for_selector("#estop-release-dialog", state="hidden", timeout=5000)
    assert posted == [] and engaged_on_server(live_server)
    assert page.locator("#estop-banner").is_visible()

    # By keyboard alone: Tab to "Release e-stop", Enter.
    page.locator("#estop-release").focus()
    page.keyboard.press("Enter")
    page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
    page.keyboard.press("Tab")
    assert page.evaluate("document.activeElement.id") == "estop-release-confirm"
    page.keyboard.press("Enter")
    page.wait_for_selector("#estop[data-engaged='no']", timeout=5000)
    assert not engaged_on_server(live_server)
    assert not dialog.is_visible() and page.locator("#estop-banner").is_hidden()
    assert frame_of(page)["content"] in ("none", "normal")
    assert page.watch.console_errors == []


def test_a_latch_engaged_elsewhere_shows_its_banner_live_and_a_release_elsewhere_closes_the_dialog(live_server, page):
    page.goto(live_server.url + "/status")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
    assert page.locator("#estop-banner").is_hidden()
    requests.post(live_server.url + "/api/estop", json={"engaged": True, "by": "curl"}, timeout=5)
    page.wait_for_selector("#estop-banner", state="visible", timeout=5000)
    assert "estop-engaged" in page.locator("body").get_attribute("class")
    page.locator("#estop-release").click()
    page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
    requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5)
    page.wait_for_selector("#estop-release-dialog", state="hidden", timeout=5000)  # nothing left to confirm
    page.wait_for_selector("#estop-banner", state="hidden", timeout=5000)
    assert page.watch.console_errors == []


def test_a_key_held_through_a_release_does_not_drive_until_pressed_again(live_server, page, ros_peer):
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, live_server.url)
    page.goto(live_server.url + "/")
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)

    page.keyboard.down("KeyW")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
    page.click("#estop-engage")  # the page sends it over its open socket
    page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=5000)
    assert requests.get(live_server.url + "/api/estop", timeout=5).json()["via"] == "websocket"
    peer.wait_for("/cmd_vel", is_zero, timeout=1)

    # Released by someone else while W is still held down on this page.
    peer.clear("/cmd_vel")
    assert requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5).status_code == 200
    page.wait_for_selector("#estop[data-engaged='no']", timeout=5000)
    page.wait_for_function("document.getElementById('teleop-message').textContent.includes('re-arm')",
                           timeout=5000)
    time.sleep(1.0)
    assert not [t for t in twists(peer) if t[1] != 0.0], "the held key moved the robot after the release"

    page.keyboard.up("KeyW")
    page.keyboard.down("KeyW")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
    page.keyboard.up("KeyW")
    peer.wait_for("/cmd_vel", is_zero, timeout=2)
    assert page.watch.console_errors == [], page.watch.console_errors


def test_a_refused_release_says_why_and_escape_then_sends_nothing_more(signed_server, page):
    """The operator is made a viewer while the dialog is open: the server refuses the release, the
    dialog says so, and closing it with Escape does not try again."""
    from tests.browser.test_auth import sign_in
    from tests.support.auth import bearer

    sign_in(page, signed_server.url, "operator")
    requests.post(signed_server.url + "/api/estop", json={"engaged": True}, headers=bearer(signed_server, "operator"),
                  timeout=5)
    page.goto(signed_server.url + "/logs")
    releases = []
    page.on("request", lambda r: r.method == "POST" and r.url.endswith("/api/estop") and releases.append(r.url))
    page.locator("#estop-release").click()
    page.wait_for_selector("#estop-release-dialog[open]", timeout=5000)
    demoted = requests.patch(signed_server.url + "/api/users/operator", json={"role": "viewer"},
                             headers=bearer(signed_server, "admin"), timeout=5)
    assert demoted.status_code == 200, demoted.text
    page.locator("#estop-release-confirm").click()
    page.wait_for_selector("#estop-release-error", state="visible", timeout=5000)
    assert page.locator("#estop-release-error").inner_text().startswith("Not released:")
    assert page.locator("#estop-release-dialog[open]").count() == 1
    page.keyboard.press("Escape")
    page.wait_for_selector("#estop-release-dialog", state="hidden", timeout=5000)
    page.wait_for_timeout(500)
    assert len(releases) == 1
    assert requests.get(signed_server.url + "/api/estop", headers=bearer(signed_server, "admin"),
                        timeout=5).json()["engaged"] is True
    assert page.locator("#estop-banner").is_visible()
