"""The Drive panel and the e-stop in a real Chromium, with a separate ROS subscriber on /cmd_vel.

The server's deadman is set to 5 s here, so every zero that arrives well within a second of
releasing the stick, hiding the tab, blurring the window or leaving the page was sent by the page
itself (or, leaving the page, by its socket closing), not by the server timing out.
"""

import json
import time

import pytest

from rover_web.linkemu import LinkEmulator, profile
from tests.browser.test_estop import release_estop
from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser

DEADMAN_S = 5.0


@pytest.fixture
def rig(live_server_factory, ros_peer):
    # No WebRTC: these tests drive the card over its WebSocket and time its zeros. With the
    # simulator's camera, the camera card's WebRTC session would move the card to its data channel
    # whenever it opened, and the move itself zeroes the robot (the socket that held control
    # closes), sometimes in the middle of a press. The move, a press held across it included, is
    # tested in tests/browser/test_webrtc.py.
    server = live_server_factory(ROVER_WEB_TELEOP_DEADMAN_S=DEADMAN_S, ROVER_WEB_WEBRTC_MAX_VIEWERS=0)
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    return server, peer


def long_link(delay_ms: float):
    """Only a one-way delay, changeable live (LinkEmulator.set_profile): no cap worth the name, a
    deep buffer, no jitter, loss, stalls or outages (bench/link.py's loopback control, delayed)."""
    return profile("custom", rate_kbps=1_000_000, buffer_kb=4096, delay_ms=delay_ms)


def open_dashboard(page, server):
    page.goto(server.url + "/")
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)


def stick_center(page):
    stick = page.locator("#teleop-joystick")
    stick.scroll_into_view_if_needed()  # the dashboard grew: the drive card may start below the fold
    box = stick.bounding_box()
    return box["x"] + box["width"] / 2, box["y"] + box["height"] / 2


def press_stick(page, dx=0.0, dy=-60.0):
    x, y = stick_center(page)
    page.mouse.move(x, y)
    page.mouse.down()
    page.mouse.move(x + dx, y + dy, steps=6)


def wait_moving(peer, predicate=lambda m: m["linear"]["x"] > 0, timeout=5.0):
    return peer.wait_for("/cmd_vel", predicate, timeout=timeout)


def assert_stops_soon(peer, t_action, what):
    zero = peer.wait_for("/cmd_vel", lambda m: is_zero(m), timeout=2.0)
    assert zero["t"] - t_action < 1.0, f"{what}: zero only after {zero['t'] - t_action:.3f} s"
    time.sleep(0.4)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in twists(peer) if t >= zero["t"]), what
    return zero


def test_joystick_drives_release_hide_blur_and_leaving_stop(rig, page, sim_process):
    server, peer = rig
    sim_process()  # the simulator rover, so the dashboard's Robot panel shows it moving
    open_dashboard(page, server)

    # Drag up: a separate ROS process sees positive linear x; the simulated rover moves.
    press_stick(page)
    wait_moving(peer)
    # 60 of 75 px up: 0.8 of 5 m/s once the drag ends.
    wait_moving(peer, lambda m: m["linear"]["x"] == pytest.approx(4.0, abs=0.1) and m["angular"]["z"] == 0)
    page.wait_for_function("Number(document.getElementById('odom-linear').textContent) > 1", timeout=10000)
    page.wait_for_function("Number(document.getElementById('teleop-linear').textContent) > 3", timeout=5000)
    assert "you" in page.locator("#teleop-holder").inner_text()

    # Release: zero.
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.mouse.up()
    assert_stops_soon(peer, t, "release")
    page.wait_for_function("Number(document.getElementById('odom-linear').textContent) === 0", timeout=10000)

    # Hidden tab (visibilitychange to hidden) while the stick is still held: zero.
    peer.clear("/cmd_vel")
    press_stick(page, dx=30)
    wait_moving(peer, lambda m: m["linear"]["x"] > 0 and m["angular"]["z"] < 0)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.evaluate("""() => {
        Object.defineProperty(document, 'visibilityState', {value: 'hidden', configurable: true});
        Object.defineProperty(document, 'hidden', {value: true, configurable: true});
        document.dispatchEvent(new Event('visibilitychange'));
    }""")
    zero = assert_stops_soon(peer, t, "hidden")
    page.evaluate("""() => {
        delete document.visibilityState; delete document.hidden;
        document.dispatchEvent(new Event('visibilitychange'));
    }""")
    page.mouse.move(*stick_center(page), steps=2)  # still held, but the page waits for a new press
    time.sleep(0.3)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    page.mouse.up()

    # Window blur, for real: another tab comes to the front (focus emulation off).
    cdp = page.context.new_cdp_session(page)
    cdp.send("Emulation.setFocusEmulationEnabled", {"enabled": False})
    other = page.context.new_page()  # opened first: a new tab on a loaded machine takes a second or more
    page.bring_to_front()
    peer.clear("/cmd_vel")
    press_stick(page)
    wait_moving(peer)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    other.bring_to_front()
    assert_stops_soon(peer, t, "blur")
    other.close()
    page.bring_to_front()
    page.mouse.up()

    # Leaving the page (pagehide) while driving: zero.
    peer.clear("/cmd_vel")
    press_stick(page)
    wait_moving(peer)
    peer.clear("/cmd_vel")
    # Timed from the page's own pagehide (wall clock, kept in sessionStorage across the
    # navigation) to the zero's publication (its source timestamp): under CI's load the
    # navigation itself once took most of a second before the page was left.
    page.evaluate("addEventListener('pagehide', () => sessionStorage.setItem('hid_at', String(Date.now())))")
    page.goto(server.url + "/api/status")
    hid_at = float(page.evaluate("sessionStorage.getItem('hid_at')")) / 1000
    # Left stopped, within a second of the pagehide (both the machine's wall clock, each twist by its
    # source timestamp). The zero that ended the motion is the close's, or, on a loaded machine, the
    # deadman's between two of the page's last frames (then nothing held is left to stop on close).
    time.sleep(1.4)
    sent = [(e["sent"], is_zero(e["msg"])) for e in peer.received("/cmd_vel")]
    assert sent and sent[-1][1], "pagehide: the robot was left moving"
    last_moving = max((t for t, zero in sent if not zero), default=None)
    stop = next(t for t, zero in sent if zero and (last_moving is None or t > last_moving))
    assert stop - hid_at < 1.0, f"pagehide: zero {stop - hid_at:.3f} s after it"
    assert page.watch.offhost == []
    assert page.watch.console_errors == []


def test_keyboard_drives_while_held_and_space_stops(rig, page):
    server, peer = rig
    open_dashboard(page, server)
    page.locator("#teleop-card h2").click()  # focus on the page, not in a text field

    page.keyboard.down("w")
    wait_moving(peer, lambda m: m["linear"]["x"] == 2.5)  # keys drive at 50% by default
    time.sleep(0.5)  # held: the page keeps it alive, the server repeats it
    assert twists(peer)[-1][1] == 2.5
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.keyboard.up("w")
    assert_stops_soon(peer, t, "key up")

    peer.clear("/cmd_vel")
    page.keyboard.down("ArrowLeft")
    page.keyboard.down("ArrowUp")
    wait_moving(peer, lambda m: m["linear"]["x"] == 2.5 and m["angular"]["z"] == 1.0)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.keyboard.press("Space")  # stops while the arrows are still down
    assert_stops_soon(peer, t, "space")
    page.keyboard.up("ArrowLeft")
    page.keyboard.up("ArrowUp")
    assert page.watch.console_errors == []


def test_estop_button_latches_across_reload_and_releases(rig, page):
    server, peer = rig
    open_dashboard(page, server)
    press_stick(page)
    wait_moving(peer)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.locator("#estop-engage").click()
    zero = assert_stops_soon(peer, t, "e-stop")
    page.wait_for_selector("#estop[data-engaged='yes']")
    page.mouse.up()

    page.reload()
    open_dashboard(page, server)
    assert page.locator("#estop").get_attribute("data-engaged") == "yes"
    assert page.locator("#estop-engage").inner_text() == "E-STOP ENGAGED"
    assert page.locator("#teleop-card").get_attribute("data-mode") == "estop"
    press_stick(page)
    time.sleep(0.5)
    page.mouse.up()
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])

    release_estop(page)
    page.wait_for_selector("#estop[data-engaged='no']")
    assert page.locator("#estop-release").is_hidden()
    press_stick(page)
    wait_moving(peer)
    page.mouse.up()
    assert page.watch.console_errors == []


def test_estop_is_on_every_page_and_follows_other_browsers(app_factory, page):
    """A plain page that extends base.html and asks for no teleop channel still shows the latch."""
    import requests
    from flask import render_template_string

    from tests.conftest import LiveServer

    app = app_factory()
    app.add_url_rule("/plain", "plain", lambda: render_template_string(
        '{% extends "base.html" %}{% block content %}<p id="plain">another page</p>{% endblock %}'))
    server = LiveServer(app)
    try:
        page.goto(server.url + "/plain")
        page.wait_for_selector("#link-server[data-state='live']", timeout=10000)
        assert page.locator("body").get_attribute("data-channels") == "status"
        assert page.locator("#estop[data-engaged='no'] #estop-engage").is_visible()
        requests.post(server.url + "/api/estop", json={"engaged": True, "by": "curl"}, timeout=5)
        page.wait_for_selector("#estop[data-engaged='yes']", timeout=5000)  # live, over SSE
        page.reload()
        assert page.locator("#estop").get_attribute("data-engaged") == "yes"  # rendered latched
        release_estop(page)
        page.wait_for_selector("#estop[data-engaged='no']", timeout=5000)
        assert requests.get(server.url + "/api/estop", timeout=5).json()["engaged"] is False
        page.locator("#estop-engage").click()
        page.wait_for_selector("#estop[data-engaged='yes']", timeout=5000)
        assert requests.get(server.url + "/api/estop", timeout=5).json()["by"].startswith("browser-")
        assert page.watch.console_errors == []
    finally:
        server.stop()


def test_second_browser_is_view_only_and_can_take_over(rig, browser):
    server, peer = rig
    ctx_a, ctx_b = browser.new_context(bypass_csp=True), browser.new_context(bypass_csp=True)
    try:
        a, b = ctx_a.new_page(), ctx_b.new_page()
        for p, name in ((a, "alice"), (b, "bob")):
            p.add_init_script(f"localStorage.setItem('rover_web.operator', '{name}')")
            open_dashboard(p, server)
        press_stick(a)
        wait_moving(peer)
        b.wait_for_function("document.getElementById('teleop-holder').textContent.includes('alice (view only)')",
                            timeout=5000)
        assert b.locator("#teleop-card").get_attribute("data-mode") == "view-only"
        assert b.locator("#teleop-takeover").is_visible()
        # Bob's stick does nothing while alice holds control.
        x, y = stick_center(b)
        b.mouse.move(x, y)
        b.mouse.down()
        b.mouse.move(x, y + 60, steps=4)
        time.sleep(0.4)
        b.mouse.up()
        assert all(lin >= 0 for _, lin, _ in twists(peer))

        b.locator("#teleop-takeover").click()
        peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
        b.wait_for_function("document.getElementById('teleop-holder').textContent.startsWith('you')", timeout=5000)
        a.wait_for_function("document.getElementById('teleop-holder').textContent.includes('bob (view only)')",
                            timeout=5000)
        a.mouse.up()
        peer.clear("/cmd_vel")
        press_stick(b, dy=60)  # backwards
        wait_moving(peer, lambda m: m["linear"]["x"] < 0)
        b.mouse.up()
    finally:
        ctx_a.close()
        ctx_b.close()


def test_the_drive_card_shows_the_link_and_says_plainly_when_it_is_too_poor(rig, page):
    """The page goes through the link emulator, whose delay is turned up once the page is live: the
    server's own measurement of the page's socket (pings the browser answers) reaches the card, and
    so does the verdict. The page's drive frames carry seq and t."""
    server, peer = rig
    link = LinkEmulator(long_link(0), "127.0.0.1:0", ("127.0.0.1", server.port)).start()
    sent = []
    page.on("websocket", lambda ws: ws.on("framesent", lambda payload: sent.append(payload)))
    try:
        page.goto(f"http://127.0.0.1:{link.port}/")
        page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
        page.wait_for_function("document.getElementById('teleop-rtt').textContent.endsWith(' ms')", timeout=10000)
        linkq = page.locator("#teleop-linkq")
        page.wait_for_selector("#teleop-linkq[data-quality='ok'], #teleop-linkq[data-quality='poor']", timeout=10000)
        assert page.locator("#teleop-stalls").inner_text() != "—"
        assert page.locator("#teleop-link-banner").is_hidden()

        press_stick(page)
        wait_moving(peer)
        time.sleep(0.3)  # a few keep-alives
        page.mouse.up()
        peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
        drives = [json.loads(f) for f in sent if '"linear"' in f]
        assert len(drives) >= 3
        seqs = [d["seq"] for d in drives]
        assert seqs == sorted(set(seqs)) and all(isinstance(d["t"], (int, float)) for d in drives)
        assert [d["t"] for d in drives] == sorted(d["t"] for d in drives)
        page.wait_for_function("document.getElementById('teleop-jitter').textContent.endsWith(' ms')",
                               timeout=5000)

        link.set_profile(long_link(450))  # each way: a 900 ms round trip
        banner = page.locator("#teleop-link-banner")
        banner.wait_for(state="visible", timeout=20000)
        text = banner.inner_text()
        assert text.startswith("Link too poor to drive safely: ") and text.endswith(" ms round trip"), text
        assert int(text.split(": ")[1].split(" ")[0].replace(",", "")) >= 600  # the locale groups digits: 1,008
        page.wait_for_selector("#teleop-linkq[data-quality='too_poor']", timeout=5000)
        page.wait_for_function("document.getElementById('teleop-quality').textContent === 'too poor' && "
                               "parseInt(document.getElementById('teleop-rtt').textContent) >= 800", timeout=10000)

        link.set_profile(long_link(0))  # the link recovers: so does the card
        banner.wait_for(state="hidden", timeout=30000)
        assert linkq.get_attribute("data-quality") in ("ok", "poor")
        assert page.watch.console_errors == []
    finally:
        link.stop()
