"""Honest state after an outage (issue 25): a page whose event stream is cut or stalled says so and
greys every live value; when the link returns it shows the current values at once and never
replays old events as new.

Chromium reaches the server through tests/support/outage_proxy.py, which can hold every byte
without closing anything: the stream stays open and silent, as over a radio that lost its peer,
so only the page's heartbeat bound can notice.
"""

import pytest

from tests.support.outage_proxy import OutageProxy
from tests.support.waiting import wait_until

pytestmark = [pytest.mark.browser, pytest.mark.ros]

ODOM = "nav_msgs/msg/Odometry"


@pytest.fixture
def live_server(live_server_factory):
    # These tests reach the page's own live.js by importing its URL, which gives the page's instance
    # only while the page loads its modules one by one: a bundle's modules are its own
    # (rover_web/web/bundles.py), so the page is served unbundled here.
    return live_server_factory(ROVER_WEB_BUNDLE=False)

# Every odom and status event the page's handlers get, with its id (live.js is a module: importing
# it again returns the page's own instance).
RECORD = """async () => {
  const src = document.querySelector('script[src*="/js/live/live."]').src;
  const live = await import(src);
  window.seen = [];
  for (const ch of ['odom', 'status']) {
    live.on(ch, (data, ev) => window.seen.push({ ch, id: Number(ev.lastEventId),
      linear: ch === 'odom' ? data.linear : null, link: document.body.dataset.link }));
  }
  // What a person sees, in order: the speed's text and the page's link state as each changes.
  window.shown = [];
  const speed = document.getElementById('odom-linear');
  const note = (what, value) => window.shown.push({ what, value, t: performance.now() });
  new MutationObserver(() => note('speed', speed.textContent))
    .observe(speed, { childList: true, characterData: true, subtree: true });
  new MutationObserver(() => note('link', document.body.dataset.link))
    .observe(document.body, { attributes: true, attributeFilter: ['data-link'] });
}"""

# Published one by one while the page cannot hear: queued in the old stream, never current.
HELD_VALUES = (0.31, 0.32, 0.33, 0.34, 0.35, 0.36)
CURRENT = 0.75

STALE_MARK = """(id) => {
  const el = document.getElementById(id);
  return { live: el.dataset.live || null, tag: getComputedStyle(el, '::after').content,
           opacity: Number(getComputedStyle(el).opacity) };
}"""


def odom(linear: float) -> dict:
    return {"twist": {"twist": {"linear": {"x": linear}}}}


@pytest.fixture
def proxied(live_server):
    with OutageProxy(live_server.port) as proxy:
        yield live_server, proxy


def test_a_stalled_link_marks_the_page_down_and_recovery_shows_current_values_without_replay(
        proxied, page, ros_peer):
    server, proxy = proxied
    peer = ros_peer("outage_odom")
    peer.advertise("/odom", ODOM)
    peer.wait_match("/odom")
    page.goto(proxy.url + "/")
    page.wait_for_selector("body[data-link='up']", timeout=15000)
    page.evaluate(RECORD)
    peer.publish("/odom", odom(0.25))
    page.wait_for_function("document.getElementById('odom-linear').textContent === '0.25'", timeout=10000)
    before = page.evaluate(STALE_MARK, "odom-linear")
    assert before == {"live": "odom", "tag": "none", "opacity": 1.0}

    proxy.hold()
    # The socket stays open and silent: only missing heartbeats (status, every second) can tell.
    page.wait_for_selector("body[data-link='down']", timeout=15000)
    assert page.locator("#link-server").get_attribute("data-state") == "lost"
    assert page.locator("#link-robot").get_attribute("data-state") == "unknown"
    held = page.evaluate(STALE_MARK, "odom-linear")
    assert held["tag"] == '"stale"' and held["opacity"] < 1, held
    assert page.locator("#estop-link").is_visible()
    assert "connection lost" in page.locator("#estop-link").inner_text()
    assert page.evaluate("Number(getComputedStyle(document.getElementById('estop-engage')).opacity)") == 1
    seen_before_resume = len(page.evaluate("window.seen"))

    # The robot's side goes on while the page cannot hear: a run of values, each one published to
    # the hub (odom is throttled to 10 Hz, so waiting for each keeps any from being conflated), so
    # the stream the page had open has every one of them queued in its socket, then the current one.
    for value in (*HELD_VALUES, CURRENT):
        peer.publish("/odom", odom(value))
        wait_until(lambda v=value: (server.rover.hub.latest("odom") or {}).get("linear") == v, 10,
                   f"the server has {value}")
    # Still down: nothing reached the page, and what it shows is still marked.
    assert page.locator("body").get_attribute("data-link") == "down"
    assert page.locator("#odom-linear").inner_text() == "0.25"
    shown_before_resume = len(page.evaluate("window.shown"))

    proxy.resume()
    page.wait_for_selector("body[data-link='up']", timeout=20000)
    page.wait_for_function(f"document.getElementById('odom-linear').textContent === '{CURRENT:.2f}'",
                           timeout=10000)
    # The held bytes of the old stream are flushed the moment the link resumes: give any that the
    # page would show time to show.
    page.wait_for_timeout(1500)
    after = page.evaluate(STALE_MARK, "odom-linear")
    assert after["tag"] == "none" and after["opacity"] == 1.0, after
    assert page.locator("#estop-link").is_hidden()

    seen = page.evaluate("window.seen")
    after_resume = [e["linear"] for e in seen[seen_before_resume:] if e["ch"] == "odom"]
    # The first odom the page heard after the outage was the current value (the new stream's
    # snapshot), and nothing older came after it: neither the value from before the outage nor any
    # of those queued during it.
    assert after_resume and after_resume[0] == CURRENT, after_resume
    assert set(after_resume) == {CURRENT}, after_resume
    # What the page showed: once the link was up again, the speed went straight to the current
    # value, within a moment (the snapshot came with the first bytes), and never showed another.
    shown = page.evaluate("window.shown")[shown_before_resume:]
    up_t = next(e["t"] for e in shown if e["what"] == "link" and e["value"] == "up")
    # The new stream's first events come together: its odom snapshot may be shown a moment before
    # its status marks the link up (the same millisecond, two events), never longer before.
    speeds = [e for e in shown if e["what"] == "speed" and e["t"] >= up_t - 50]
    assert speeds and {e["value"] for e in speeds} == {f"{CURRENT:.2f}"}, shown  # (a repeated snapshot rewrites it)
    assert speeds[0]["t"] - up_t < 2000, shown
    assert not [e for e in shown if e["what"] == "speed" and e["t"] < up_t - 50], shown  # nothing while down
    # ...and no event was handed to the page twice or after a newer one, on either channel.
    for ch in ("odom", "status"):
        ids = [e["id"] for e in seen if e["ch"] == ch]
        assert ids == sorted(set(ids)), (ch, ids)
    assert page.watch.console_errors == [], page.watch.console_errors


def test_a_page_opened_while_the_link_is_up_is_not_marked_stale(proxied, page):
    server, proxy = proxied
    page.goto(proxy.url + "/")
    page.wait_for_selector("body[data-link='up']", timeout=15000)
    page.wait_for_selector("#status-uptime[data-live='status']", timeout=10000)
    assert page.evaluate(STALE_MARK, "status-uptime")["tag"] == "none"
