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

# Every odom and status event the page's handlers get, with its id (live.js is a module: importing
# it again returns the page's own instance).
RECORD = """async () => {
  const src = document.querySelector('script[src*="/js/live.js"]').src;
  const live = await import(src);
  window.seen = [];
  for (const ch of ['odom', 'status']) {
    live.on(ch, (data, ev) => window.seen.push({ ch, id: Number(ev.lastEventId),
      linear: ch === 'odom' ? data.linear : null, link: document.body.dataset.link }));
  }
}"""

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

    # A new value, published by the robot's side while the page cannot hear it.
    peer.publish("/odom", odom(0.75))
    wait_until(lambda: (server.rover.hub.latest("odom") or {}).get("linear") == 0.75, 10, "the server has 0.75")
    # Still down: nothing reached the page, and what it shows is still marked.
    assert page.locator("body").get_attribute("data-link") == "down"
    assert page.locator("#odom-linear").inner_text() == "0.25"

    proxy.resume()
    page.wait_for_selector("body[data-link='up']", timeout=20000)
    page.wait_for_function("document.getElementById('odom-linear').textContent === '0.75'", timeout=10000)
    after = page.evaluate(STALE_MARK, "odom-linear")
    assert after["tag"] == "none" and after["opacity"] == 1.0, after
    assert page.locator("#estop-link").is_hidden()

    seen = page.evaluate("window.seen")
    after_resume = seen[seen_before_resume:]
    assert [e for e in after_resume if e["ch"] == "odom"], "no odom event after the outage"
    # Nothing from before the outage came back: after it, odom only ever carried the new value...
    assert {e["linear"] for e in after_resume if e["ch"] == "odom"} == {0.75}
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
