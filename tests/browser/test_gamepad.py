"""The Drive card's gamepad in a real Chromium, with a scripted pad and a separate ROS subscriber.

The pad is an init script standing in for `navigator.getGamepads()`: the test sets its axes and
buttons and fires `gamepadconnected` / `gamepaddisconnected` as a browser does. The server's
deadman is 5 s here (as in test_teleop.py), so a zero that arrives within a second of letting go
of enable, unplugging the pad or hiding the tab was sent by the page, not by the server timing out.
The pure mapping (static/js/teleop/gamepad.js) is tested on its own at the end.
"""

import time

import pytest

from rover_web.teleop.service import TeleopService
from tests.browser.test_auth import sign_in
from tests.browser.test_estop import release_estop
from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser

DEADMAN_S = 5.0

# A standard-mapping pad under the test's control: window.__pad.connect(), .set({axes, enable,
# buttons}), .disconnect(). `wobble` moves the stick a little on every read, as a real stick's noise
# and a moving thumb do, to show that frames go out at the teleop rate, not once per frame drawn.
SCRIPTED_PAD = """
(() => {
  const pads = [];
  let wobble = false;
  const fire = (type, pad) => {
    const e = new Event(type);
    Object.defineProperty(e, 'gamepad', { value: pad });
    window.dispatchEvent(e);
  };
  window.__pad = {
    reads: 0,
    connect(id = 'Scripted Pad (STANDARD GAMEPAD Vendor: 0000 Product: 0000)', index = 0) {
      const pad = { id, index, connected: true, mapping: 'standard', timestamp: performance.now(),
                    axes: [0, 0, 0, 0],
                    buttons: Array.from({ length: 17 }, () => ({ pressed: false, touched: false, value: 0 })) };
      pads[index] = pad;
      fire('gamepadconnected', pad);
    },
    set({ axes, enable, buttons } = {}, index = 0) {
      const pad = pads[index];
      if (axes) axes.forEach((v, i) => { pad.axes[i] = v; });
      const press = (i, on) => { pad.buttons[i] = { pressed: on, touched: on, value: on ? 1 : 0 }; };
      if (enable !== undefined) press(4, enable);
      if (buttons) Object.entries(buttons).forEach(([i, on]) => press(Number(i), on));
      pad.timestamp = performance.now();
    },
    wobble(on) { wobble = on; },
    disconnect(index = 0) {
      const pad = pads[index];
      pads[index] = null;
      pad.connected = false;
      fire('gamepaddisconnected', pad);
    },
  };
  Object.defineProperty(Navigator.prototype, 'getGamepads', { configurable: true, value() {
    window.__pad.reads += 1;
    if (wobble && pads[0]) pads[0].axes[1] = -0.5 - 0.4 * Math.abs(Math.sin(performance.now() / 37));
    return pads.map((p) => p || null);
  } });
})();
"""


@pytest.fixture
def rig(live_server_factory, ros_peer):
    server = live_server_factory(ROVER_WEB_TELEOP_DEADMAN_S=DEADMAN_S)
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, server.url)
    return server, peer


def open_dashboard(page, server):
    page.add_init_script(SCRIPTED_PAD)
    page.goto(server.url + "/")
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)


def pad(page, **state):
    page.evaluate("(s) => window.__pad.set(s)", state)


def press_enable_again(page):
    """Let go of enable until the page has read it, then press it: a real thumb takes longer than a frame."""
    pad(page, enable=False)
    page.wait_for_selector("#gamepad[data-state='connected']", timeout=5000)
    pad(page, enable=True)


def card(page, id_):
    return page.locator(f"#{id_}").inner_text()


def assert_stops_soon(peer, t_action, what):
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    assert zero["t"] - t_action < 1.0, f"{what}: zero only after {zero['t'] - t_action:.3f} s"
    time.sleep(0.4)
    assert all(lin == 0.0 and ang == 0.0 for t, lin, ang in twists(peer) if t >= zero["t"]), what
    return zero


def test_stick_drives_only_while_enable_is_held_and_release_or_unplug_stops(rig, page):
    server, peer = rig
    open_dashboard(page, server)
    assert card(page, "gamepad-name").startswith("none connected")
    page.evaluate("window.__pad.connect()")
    page.wait_for_selector("#gamepad[data-state='connected']", timeout=5000)
    assert card(page, "gamepad-name").startswith("Scripted Pad (STANDARD GAMEPAD")

    # Full forward and half a turn to the right (0.575 is half-way out of the 0.15 dead zone), no enable.
    pad(page, axes=[0.575, -1.0])
    page.wait_for_function("document.getElementById('gamepad-stick').textContent === 'linear 1.00, angular -0.50'",
                           timeout=5000)
    assert card(page, "gamepad-enable") == "released"
    time.sleep(0.5)
    assert twists(peer) == [] and server.rover.feature(TeleopService).controller.state()["holder"] is None

    # Enable held: a separate ROS process sees the motion, at the maxima (5 m/s, 2 rad/s) times the stick.
    pad(page, enable=True)
    peer.wait_for("/cmd_vel", lambda m: (m["linear"]["x"], m["angular"]["z"]) == (5.0, -1.0), timeout=5.0)
    page.wait_for_selector("#gamepad[data-state='driving']", timeout=5000)
    assert card(page, "gamepad-enable") == "held"
    page.wait_for_function("document.getElementById('teleop-source').textContent === 'gamepad'", timeout=5000)
    assert server.rover.hub.latest("teleop")["source"] == "gamepad"
    assert "you" in card(page, "teleop-holder")

    # Inside the dead zone the robot holds still, enable or not.
    pad(page, axes=[0.1, -0.12])
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    pad(page, axes=[0.0, -0.5])
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == pytest.approx(5.0 * 0.35 / 0.85, abs=0.01), timeout=2.0)

    # Enable let go with the stick still pushed: zero, and nothing after it.
    peer.clear("/cmd_vel")
    t = time.monotonic()
    pad(page, enable=False)
    assert_stops_soon(peer, t, "enable released")
    assert card(page, "gamepad-enable") == "released"

    # Enable again: moving (seen after the clear: the release's buffer still holds the stick's last
    # motion); then the pad is unplugged mid-drive: zero.
    peer.clear("/cmd_vel")
    pad(page, enable=True)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 1, timeout=5.0)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.evaluate("window.__pad.disconnect()")
    stopped = assert_stops_soon(peer, t, "gamepad disconnected")
    page.wait_for_selector("#gamepad[data-state='none']", timeout=5000)

    # Plugged in again with enable already held: it must be let go and pressed again first.
    # (From the stop on: a command sent just before the unplug may still land after the clear.)
    page.evaluate("window.__pad.connect(); window.__pad.set({axes: [0, -1], enable: true})")
    page.wait_for_selector("#gamepad[data-state='blocked']", timeout=5000)
    time.sleep(0.4)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= stopped["t"])
    press_enable_again(page)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    pad(page, enable=False)
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    assert page.watch.console_errors == []


def test_a_hidden_tab_stops_the_gamepad_and_frames_go_out_at_the_teleop_rate(rig, page):
    server, peer = rig
    frames = []
    page.on("websocket", lambda ws: ws.on("framesent", lambda payload: frames.append((time.monotonic(), payload))))
    open_dashboard(page, server)
    page.evaluate("window.__pad.connect()")
    pad(page, axes=[0, -1], enable=True)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)

    # The stick moves on every read: the page reads at the animation frame rate but sends at most
    # one frame per teleop period (25 ms at 40 Hz) and no more than it reads.
    page.evaluate("window.__pad.wobble(true)")
    time.sleep(0.3)
    reads_before, t0 = page.evaluate("window.__pad.reads"), time.monotonic()
    sent_before = len(frames)
    time.sleep(1.0)
    reads, t1 = page.evaluate("window.__pad.reads") - reads_before, time.monotonic()
    drives = [p for t, p in frames[sent_before:] if '"gamepad"' in p]
    page.evaluate("window.__pad.wobble(false)")
    pad(page, axes=[0, -1])
    assert reads > len(drives) > 5, (reads, len(drives))
    assert len(drives) <= 40 * (t1 - t0) + 2, len(drives)

    # Hidden tab while enable is held: zero; visible again, still held: nothing until pressed again.
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.evaluate("""() => {
        Object.defineProperty(document, 'visibilityState', {value: 'hidden', configurable: true});
        Object.defineProperty(document, 'hidden', {value: true, configurable: true});
        document.dispatchEvent(new Event('visibilitychange'));
    }""")
    zero = assert_stops_soon(peer, t, "hidden")
    reads_hidden = page.evaluate("window.__pad.reads")
    time.sleep(0.3)
    assert page.evaluate("window.__pad.reads") == reads_hidden  # no polling while hidden
    page.evaluate("""() => {
        delete document.visibilityState; delete document.hidden;
        document.dispatchEvent(new Event('visibilitychange'));
    }""")
    page.wait_for_selector("#gamepad[data-state='blocked']", timeout=5000)
    time.sleep(0.3)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    press_enable_again(page)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    pad(page, enable=False)
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    assert page.watch.console_errors == []


def test_estop_stops_the_gamepad_and_a_held_stick_must_come_back_to_rearm(rig, page):
    server, peer = rig
    open_dashboard(page, server)
    page.evaluate("window.__pad.connect()")
    pad(page, axes=[0, -1], enable=True)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.locator("#estop-engage").click()
    zero = assert_stops_soon(peer, t, "e-stop")
    page.wait_for_selector("#teleop-card[data-mode='estop']", timeout=5000)

    # Released with enable and the stick still held: nothing moves until the stick comes back.
    release_estop(page)
    page.wait_for_selector("#estop[data-engaged='no']", timeout=5000)
    page.wait_for_function("document.getElementById('teleop-message').textContent.includes('to re-arm')",
                           timeout=5000)
    pad(page, axes=[0, -0.9])  # a changed value, still pushed: refused as well
    time.sleep(0.4)
    assert all(lin == 0.0 for t, lin, _ in twists(peer) if t >= zero["t"])
    pad(page, axes=[0, 0])     # neutral, enable still held: re-armed
    page.wait_for_function("document.getElementById('gamepad-stick').textContent === 'linear 0.00, angular 0.00'",
                           timeout=5000)
    time.sleep(0.1)
    pad(page, axes=[0, -1])
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    pad(page, enable=False)
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    assert page.watch.console_errors == []


def test_a_reading_that_stalls_while_enable_is_held_stops_the_robot(rig, page):
    """No animation frame while the page stays visible (a stalled page): the held command is not
    repeated from a stale reading; the page says stop within its keep-alive, long before the 5 s deadman."""
    server, peer = rig
    page.add_init_script("""(() => {
        const real = window.requestAnimationFrame.bind(window);
        let paused = false;
        const held = [];
        window.requestAnimationFrame = (cb) => (paused ? (held.push(cb), -1) : real(cb));
        window.__raf = { pause() { paused = true; },
                         resume() { paused = false; held.splice(0).forEach((cb) => real(cb)); } };
    })()""")
    open_dashboard(page, server)
    page.evaluate("window.__pad.connect()")
    pad(page, axes=[0, -1], enable=True)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    peer.clear("/cmd_vel")
    t = time.monotonic()
    page.evaluate("window.__raf.pause()")
    assert_stops_soon(peer, t, "stalled reading")
    page.evaluate("window.__raf.resume()")
    page.wait_for_selector("#gamepad[data-state='blocked']", timeout=5000)
    press_enable_again(page)
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 5.0, timeout=5.0)
    pad(page, enable=False)
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    assert page.watch.console_errors == []


def test_axes_inversion_dead_zone_and_enable_button_are_set_on_the_card_and_kept(rig, page):
    server, peer = rig
    open_dashboard(page, server)
    page.locator(".gamepad-settings summary").click()
    page.fill("#gamepad-linear-axis", "3")      # the right stick's y
    page.fill("#gamepad-angular-axis", "2")
    page.check("#gamepad-invert-linear")
    page.fill("#gamepad-dead-zone", "0.5")
    page.fill("#gamepad-enable-button", "5")    # the right shoulder
    page.fill("#gamepad-dead-zone", "7")        # out of range: back to the default
    page.locator("#gamepad-enable-button").press("Tab")
    stored = page.evaluate("JSON.parse(localStorage.getItem('rover_web.gamepad'))")
    assert stored == {"linearAxis": 3, "angularAxis": 2, "invertLinear": True, "invertAngular": False,
                      "deadZone": 0.15, "enableButton": 5}
    assert page.input_value("#gamepad-dead-zone") == "0.15"

    page.reload()
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
    assert page.input_value("#gamepad-linear-axis") == "3" and page.is_checked("#gamepad-invert-linear")
    page.evaluate("window.__pad.connect()")
    # The left stick and button 4 do nothing now.
    pad(page, axes=[0, -1, 0, 0], enable=True)
    page.wait_for_selector("#gamepad[data-state='connected']", timeout=5000)
    time.sleep(0.4)
    assert twists(peer) == []
    # Right stick up (inverted: backwards) with button 5.
    pad(page, axes=[0, 0, 0, -1], buttons={5: True})
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == -5.0 and m["angular"]["z"] == 0.0, timeout=5.0)
    pad(page, buttons={5: False})
    peer.wait_for("/cmd_vel", is_zero, timeout=2.0)
    page.locator(".gamepad-settings summary").click()
    page.click("#gamepad-reset")
    assert page.evaluate("JSON.parse(localStorage.getItem('rover_web.gamepad'))")["enableButton"] == 4
    assert page.input_value("#gamepad-linear-axis") == "1" and not page.is_checked("#gamepad-invert-linear")
    assert page.watch.console_errors == []


def test_without_the_gamepad_api_the_card_says_why(live_server, page):
    page.add_init_script("delete Navigator.prototype.getGamepads")
    page.goto(live_server.url + "/")
    page.wait_for_selector("#gamepad[data-state='unavailable']", timeout=10000)
    assert "secure pages (localhost or HTTPS)" in card(page, "gamepad-name")
    assert "secure pages (localhost or HTTPS)" in card(page, "teleop-card")
    assert page.watch.console_errors == []


def test_a_viewer_gets_no_gamepad_driving(signed_server, page):
    page.add_init_script(SCRIPTED_PAD)
    sign_in(page, signed_server.url, "viewer")
    page.evaluate("window.__pad.connect(); window.__pad.set({axes: [0, -1], enable: true})")
    time.sleep(0.5)
    assert card(page, "gamepad-name") == "view only"
    assert page.evaluate("window.__pad.reads") == 0  # not even read
    assert page.locator("#gamepad-enable-button").is_disabled()
    state = signed_server.rover.feature(TeleopService).controller.state()
    assert state["operators"] == 0 and state["linear_mps"] == 0.0
    assert page.watch.console_errors == [], page.watch.console_errors


# --- the pure module, on its own ---

@pytest.fixture
def blank(live_server, page):
    page.goto(live_server.url + "/static/js/teleop/gamepad.js")  # same origin, and no page script of its own
    return page


def test_mapping_dead_zone_inversion_and_config(blank):
    got = blank.evaluate("""async () => {
        const g = await import('/static/js/teleop/gamepad.js');
        const cfg = g.normalizeConfig({});
        const pad = (axes, pressed = [], extra = {}) => ({ axes, buttons: Array.from({ length: 17 },
            (_, i) => ({ pressed: pressed.includes(i), value: pressed.includes(i) ? 1 : 0 })), ...extra });
        return {
            defaults: cfg,
            deadZone: [0, 0.1, 0.15, -0.15, 0.2, 0.575, -0.575, 1, -1, 1.7, NaN, Infinity, '0.5', null]
                .map((v) => g.applyDeadZone(v, 0.15)),
            zeroDeadZone: [0.01, -0.5, 1].map((v) => g.applyDeadZone(v, 0)),
            upLeft: g.readPad(pad([-1, -1], [4]), cfg),
            downRight: g.readPad(pad([0.575, 1]), cfg),
            inverted: g.readPad(pad([0.575, -1]), { ...cfg, invertLinear: true, invertAngular: true }),
            otherAxes: g.readPad(pad([0.9, 0.9, -0.3, 0.8]), { ...cfg, linearAxis: 3, angularAxis: 2 }),
            missingAxes: g.readPad(pad([]), { ...cfg, linearAxis: 9 }),
            nanAxis: g.readPad(pad([NaN, Infinity]), cfg),
            tiny: g.readPad(pad([0.1500001, -0.1500004]), cfg),
            analogTrigger: [0.3, 0.6].map((value) => g.buttonHeld({ buttons: [{ pressed: false, value }] }, 0)),
            oldStyle: g.buttonHeld({ buttons: [1] }, 0),
            noButton: g.buttonHeld({ buttons: [] }, 4) || g.buttonHeld(null, 4),
            normalized: [
                g.normalizeConfig({ linearAxis: '3', angularAxis: 2, invertLinear: true, deadZone: '0.3',
                                    enableButton: '5' }),
                g.normalizeConfig({ linearAxis: -1, angularAxis: 1.5, invertAngular: 'yes', deadZone: 0.95,
                                    enableButton: 32 }),
                g.normalizeConfig({ linearAxis: '', deadZone: '', enableButton: null }),
                g.normalizeConfig(null),
            ],
        };
    }""")
    assert got["defaults"] == {"linearAxis": 1, "angularAxis": 0, "invertLinear": False, "invertAngular": False,
                               "deadZone": 0.15, "enableButton": 4}
    assert got["deadZone"] == pytest.approx([0, 0, 0, 0, 0.05 / 0.85, 0.5, -0.5, 1, -1, 1, 0, 0, 0, 0])
    assert got["zeroDeadZone"] == pytest.approx([0.01, -0.5, 1])
    # Stick up is forward (+linear), left is a left turn (+angular, REP 103).
    assert got["upLeft"] == {"enable": True, "linear": 1, "angular": 1, "raw": [-1, -1]}
    assert got["downRight"] == {"enable": False, "linear": -1, "angular": -0.5, "raw": [1, 0.575]}
    assert got["inverted"] == {"enable": False, "linear": -1, "angular": 0.5, "raw": [-1, 0.575]}
    assert got["otherAxes"]["linear"] == pytest.approx(-0.765) and got["otherAxes"]["angular"] == pytest.approx(0.176)
    assert got["missingAxes"]["linear"] == 0 and got["nanAxis"]["linear"] == 0 and got["nanAxis"]["angular"] == 0
    assert got["tiny"]["linear"] == 0 and got["tiny"]["angular"] == 0  # never -0 in a frame
    assert got["analogTrigger"] == [False, True] and got["oldStyle"] is True and got["noButton"] is False
    defaults = got["defaults"]
    assert got["normalized"] == [
        {"linearAxis": 3, "angularAxis": 2, "invertLinear": True, "invertAngular": False, "deadZone": 0.3,
         "enableButton": 5},
        defaults, defaults, defaults]


def test_enable_gate_and_pacing(blank):
    got = blank.evaluate("""async () => {
        const g = await import('/static/js/teleop/gamepad.js');
        const r = (enable, linear = 0.5, angular = 0) => ({ enable, linear, angular });
        const gate = new g.EnableGate();
        const seq = [gate.command(r(false)), gate.command(r(true)), gate.command(null)];
        gate.command(r(true));
        gate.block();                                // a page stop while enable is held
        seq.push(gate.command(r(true)), gate.command(r(true, 0)), gate.command(r(false)), gate.command(r(true)));
        const a = { linear: 0.5, angular: 0 }, b = { linear: 0.6, angular: 0 };
        const pace = [
            g.pace(null, null, 100, 0, 25), g.pace(null, a, 100, 90, 25), g.pace(a, null, 100, 99, 25),
            g.pace(a, { ...a }, 200, 0, 25), g.pace(a, b, 110, 90, 25), g.pace(a, b, 115, 90, 25),
        ];
        return { seq, pace };
    }""")
    assert got["seq"] == [None, {"linear": 0.5, "angular": 0}, None, None, None, None,
                          {"linear": 0.5, "angular": 0}]
    assert got["pace"] == [None, "drive", "stop", None, None, "drive"]
