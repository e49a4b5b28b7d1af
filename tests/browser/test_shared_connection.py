"""Issue 15, an e-stop that is always reachable: Chromium allows six HTTP/1.1 connections per host
for all the tabs of a profile (a Playwright context), so eight dashboard tabs must share one event
stream and hidden tabs must let go of their camera stream.

Hidden tabs are emulated: headless Chromium shows every page as visible, whether it is in the
background, in a window of its own or in a minimised one (Browser.setWindowBounds), so the tests
redefine document.hidden and document.visibilityState and dispatch visibilitychange, which is
what the pages listen to. A dead leader is a tab whose main thread is kept busy: CDP's
Page.setWebLifecycleState "frozen" did not stop that tab from relaying events (Chromium 156).

These pages are not routed through PageWatch: a route handler runs in this process and would add
its latency to every request, the e-stop's too. Their console errors are still collected.
"""

from __future__ import annotations

import time

import pytest
import requests

from tests.support.waiting import wait_until

pytestmark = pytest.mark.browser

TABS = 8


@pytest.fixture
def live_server(live_server_factory):
    # These tests reach the page's own live.js by importing its URL, which gives the page's instance
    # only while the page loads its modules one by one: a bundle's modules are its own
    # (rover_web/web/bundles.py), so the page is served unbundled here.
    return live_server_factory(ROVER_WEB_BUNDLE=False)

SET_HIDDEN = """(hidden) => {
    Object.defineProperty(document, 'hidden', { value: hidden, configurable: true });
    Object.defineProperty(document, 'visibilityState', { value: hidden ? 'hidden' : 'visible', configurable: true });
    document.dispatchEvent(new Event('visibilitychange'));
}"""

# A tab whose main thread is stuck, as in a long task or a debugger: it relays nothing meanwhile.
HANG = "(ms) => { setTimeout(() => { const end = Date.now() + ms; while (Date.now() < end); }, 0); }"

# live.js is one module instance per page, so a handler added here sees what the page's own see.
COLLECT = """async (channel) => {
    const { on } = await import('/static/js/live/live.js');
    window.collected = window.collected || {};
    window.collected[channel] = [];
    on(channel, (data, ev) => window.collected[channel].push(ev.lastEventId));
}"""


@pytest.fixture
def context(browser):
    ctx = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True)
    ctx.console_errors = []
    ctx.on("console", lambda m: m.type == "error" and ctx.console_errors.append(m.text))
    yield ctx
    ctx.close()


def open_tabs(context, url: str, n: int = TABS, one_window: bool = False) -> list:
    """n tabs of url; with one_window, each new tab hides the one before, as in one browser window."""
    pages = []
    for _ in range(n):
        if one_window and pages:
            pages[-1].evaluate(SET_HIDDEN, True)
        page = context.new_page()
        page.on("pageerror", lambda e: context.console_errors.append(f"pageerror: {e}"))
        page.goto(url, wait_until="domcontentloaded")
        pages.append(page)
    for page in pages:
        page.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    return pages


def roles(pages) -> list[str]:
    return [p.get_attribute("#link-server", "data-role") for p in pages]


def leader_of(pages):
    found = [p for p, role in zip(pages, roles(pages), strict=True) if role == "leader"]
    assert len(found) == 1, roles(pages)
    return found[0]


def collected(page, channel: str) -> list[str]:
    return page.evaluate("(ch) => window.collected[ch]", channel)


def streams(server) -> int:
    return server.rover.hub.client_count


def assert_one_stream_for_a_while(server, seconds: float = 2.0) -> None:
    # Followers answer every heartbeat; none of that may make the leader open a second stream.
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        assert streams(server) == 1
        time.sleep(0.1)


def test_eight_tabs_share_one_event_stream_and_a_closed_leader_hands_it_over(live_server, context):
    pages = open_tabs(context, live_server.url + "/")
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream for eight tabs")
    assert sorted(roles(pages)) == ["follower"] * (TABS - 1) + ["leader"]
    assert_one_stream_for_a_while(live_server)
    assert requests.get(live_server.url + "/api/status", timeout=5).json()["sse_clients"] == 1

    leader = leader_of(pages)
    leader.close()
    rest = [p for p in pages if p is not leader]
    wait_until(lambda: roles(rest).count("leader") == 1, 10, "another tab leading")
    for page in rest:
        page.evaluate(COLLECT, "status")
    wait_until(lambda: all(len(collected(p, "status")) >= 2 for p in rest), 10, "status in every remaining tab")
    wait_until(lambda: streams(live_server) == 1, 10, "the closed leader's stream gone")
    assert_one_stream_for_a_while(live_server)
    assert all(p.get_attribute("#link-server", "data-state") == "live" for p in rest)
    assert context.console_errors == []


def test_a_hung_leader_is_replaced_and_its_stale_events_are_ignored_when_it_resumes(live_server, context):
    pages = open_tabs(context, live_server.url + "/", 3)
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream")
    for page in pages:
        page.evaluate(COLLECT, "status")
    leader = leader_of(pages)
    rest = [p for p in pages if p is not leader]
    # It keeps its lock and its socket; only its silence tells.
    leader.evaluate(HANG, 8000)
    wait_until(lambda: roles(rest).count("leader") == 1, 8, "a follower taking over from the hung leader")
    before = [len(collected(p, "status")) for p in rest]
    wait_until(lambda: all(len(collected(p, "status")) >= n + 2 for p, n in zip(rest, before, strict=True)), 10,
               "status in the other tabs")
    assert all(p.get_attribute("#link-server", "data-state") == "live" for p in rest)

    # When it resumes it relays the events it had queued, then learns it lost the lock.
    wait_until(lambda: leader.get_attribute("#link-server", "data-role") == "follower", 15,
               "the resumed tab following")
    assert roles(pages).count("leader") == 1
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream again")
    n = len(collected(leader, "status"))
    wait_until(lambda: len(collected(leader, "status")) >= n + 2, 10, "status in the resumed tab")
    for page in pages:
        ids = [int(i) for i in collected(page, "status")]
        assert ids == sorted(set(ids)), "a status event came twice or out of order"
    assert context.console_errors == []


def test_ring_events_reach_every_tab_once_across_a_hand_over_and_not_a_tab_that_joins_later(live_server,
                                                                                            context):
    hub = live_server.rover.hub
    pages = open_tabs(context, live_server.url + "/", 3)
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream")
    for page in pages:
        page.evaluate(COLLECT, "panel_log")
    # No panel on the page has this id, so panels.js leaves its log alone.
    ids = [str(hub.emit("panel_log", {"panel": "no_such_panel", "n": n})) for n in range(5)]
    wait_until(lambda: all(collected(p, "panel_log") == ids for p in pages), 10, "five log events in each tab")

    leader = leader_of(pages)
    leader.close()
    rest = [p for p in pages if p is not leader]
    # Emitted while the stream changes hands: the new leader resumes after the last id it saw.
    ids += [str(hub.emit("panel_log", {"panel": "no_such_panel", "n": n})) for n in range(5, 10)]
    wait_until(lambda: roles(rest).count("leader") == 1, 10, "another tab leading")
    ids += [str(hub.emit("panel_log", {"panel": "no_such_panel", "n": n})) for n in range(10, 15)]
    wait_until(lambda: all(collected(p, "panel_log") == ids for p in rest), 10, "fifteen log events in each tab")

    late = open_tabs(context, live_server.url + "/", 1)[0]
    late.evaluate(COLLECT, "panel_log")
    last = str(hub.emit("panel_log", {"panel": "no_such_panel", "n": 15}))
    wait_until(lambda: collected(late, "panel_log") == [last], 10, "only the new log event in the new tab")
    page = rest[0]
    page.wait_for_timeout(500)  # a repeat would come right after the first
    assert all(collected(p, "panel_log") == [*ids, last] for p in rest)
    assert context.console_errors == []


def test_estop_reaches_the_server_within_a_second_with_eight_tabs_open(live_server, sim_process, context):
    sim_process()  # every dashboard shows the simulated camera
    # Over MJPEG, the stream that shares the tabs' HTTP/1.1 connections with the e-stop's POST.
    context.add_init_script("localStorage.setItem('rover_web.camera.transport', 'mjpeg')")
    pages = open_tabs(context, live_server.url + "/", one_window=True)
    camera = lambda: requests.get(live_server.url + "/api/camera/streams", timeout=5).json()["viewers"]  # noqa: E731
    wait_until(lambda: camera() == 1, 15, "one camera stream, the visible tab's")
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream")
    assert not requests.get(live_server.url + "/api/estop", timeout=5).json()["engaged"]

    # Timed from the click in the page to the server's own record, so neither Playwright's way to
    # the page nor this test's polling counts.
    pages[-1].evaluate("() => document.addEventListener('click', () => { window.clickedAt = Date.now() / 1000; },"
                       " { capture: true })")
    pages[-1].locator("#estop-engage").click()
    state = wait_until(lambda: (r := requests.get(live_server.url + "/api/estop", timeout=5).json())["engaged"] and r,
                       10, "the e-stop engaged")
    took = state["since"] - pages[-1].evaluate("window.clickedAt")
    assert took < 1.0, f"the e-stop reached the server {took:.2f} s after the click"
    # The page confirms from the server's reply; eight tabs decoding MJPEG on two busy cores make it slow.
    pages[-1].wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=15000)


def test_a_hidden_tab_closes_its_camera_stream_and_opens_it_again_when_shown(live_server, sim_process, context):
    sim_process()
    context.add_init_script("localStorage.setItem('rover_web.camera.transport', 'mjpeg')")  # MJPEG's test
    viewers = lambda: requests.get(live_server.url + "/api/camera/streams", timeout=5).json()["viewers"]  # noqa: E731
    pages = open_tabs(context, live_server.url + "/", 2)
    wait_until(lambda: viewers() == 2, 20, "both tabs streaming the camera")
    pages[1].evaluate(SET_HIDDEN, True)
    wait_until(lambda: viewers() == 1, 10, "the hidden tab's stream closed")
    assert pages[1].get_attribute("#camera-image", "src").startswith("data:")
    pages[1].evaluate(SET_HIDDEN, False)
    wait_until(lambda: viewers() == 2, 10, "the stream back in the tab shown again")
    pages[1].wait_for_function("() => { const i = document.getElementById('camera-image');"
                               " return i.src.startsWith('blob:') && i.complete && i.naturalWidth === 640; }",
                               timeout=15000)
    assert context.console_errors == []


def test_a_tab_asking_for_a_channel_the_server_lacks_does_not_stop_the_others(live_server, context):
    url = live_server.url + "/"
    warnings = []
    context.on("console", lambda m: m.type == "warning" and warnings.append(m.text))
    pages = open_tabs(context, url, 2)
    wait_until(lambda: streams(live_server) == 1, 10, "one event stream")
    # As a tab opened before the server was upgraded to one without that channel.
    odd = context.new_page()
    odd.route(url, lambda route: route.fulfill(response=(r := route.fetch()), body=r.text().replace(
        'data-channels="', 'data-channels="no_such_channel,', 1)))
    pages.append(odd)
    odd.goto(url)
    odd.wait_for_selector("#link-server[data-state='live']", timeout=15000)
    for page in pages:
        page.evaluate(COLLECT, "status")
    wait_until(lambda: all(len(collected(p, "status")) >= 2 for p in pages), 15, "status in every tab")
    assert any("no event channel no_such_channel" in w for w in warnings), warnings
    assert streams(live_server) == 1


def test_without_web_locks_every_tab_keeps_a_stream_of_its_own(live_server, context):
    # As over plain http to the robot's address: navigator.locks exists only in secure contexts.
    context.add_init_script("Object.defineProperty(Navigator.prototype, 'locks', { get: () => undefined });")
    pages = open_tabs(context, live_server.url + "/", 2)
    assert roles(pages) == ["own", "own"]
    wait_until(lambda: streams(live_server) == 2, 10, "a stream for each tab")
    assert context.console_errors == []
