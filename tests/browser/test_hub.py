"""The fleet hub's page in Chromium: a robot heard over real Zenoh appears, in the table and on the
map (where it dims once lost), and "Stop all" shows its answer. The robot here is a light one in
this process (a Zenoh session with a token, signed summaries and a stop queryable, as
bench/hub.py's); tests/integration/hub has real rover_webs."""

from __future__ import annotations

import json
import threading

import pytest
from werkzeug.serving import make_server

from rover_web.zenoh_link import signing
from tests.browser.test_a11y_audit import AXE_URL, SIZES, THEMES, audit
from tests.browser.test_languages import NOT_INTERFACE, READ_TEXT, english_patterns, leftovers
from tests.conftest import free_port
from tests.unit.zenoh_link.test_alerts import breach_alerts

pytestmark = pytest.mark.browser

KEY = b"k" * 64
ALPHA_URL = "http://127.0.0.1:9/robots/alpha/"
ALPHA_AT = {"lng": -82.4501234, "lat": 27.3705678}


class LightRobot:
    """alpha of fleet `fleet`: summaries every 0.3 s until closed; engaged once a stop checks.

    Its summary's position is whatever `position` holds (a robot's comes from its GPS fix)."""

    def __init__(self, endpoint: str):
        import zenoh

        config = zenoh.Config()
        config.insert_json5("mode", '"client"')
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        self.session = zenoh.open(config)
        self.endpoint = endpoint
        self.engaged = False
        self.position = None
        self.alerts: tuple[list, list] = ([], [])  # English, and each one's wire form (robot_summary's)
        self.guard = signing.ReplayGuard(10.0)
        self.token = self.session.liveliness().declare_token("rover_web/fleet/alpha/alive")
        self.queryable = self.session.declare_queryable("rover_web/fleet/alpha/stop", self._on_stop)
        self.publisher = self.session.declare_publisher("rover_web/fleet/alpha/summary")
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._publish, daemon=True)
        self.thread.start()

    def _on_stop(self, query) -> None:
        command = self.guard.check(KEY, "fleet", "alpha", json.loads(query.payload.to_bytes()))
        self.engaged = True
        query.reply(query.key_expr, json.dumps(signing.answer(KEY, "fleet", "alpha", command["nonce"], "engaged")))

    def _publish(self) -> None:
        seq = 0
        while not self.done.wait(0.3):
            seq += 1
            summary = {"title": "Alpha", "url": ALPHA_URL, "link": "ok",
                       "mode": "estop" if self.engaged else "idle", "estop": {"engaged": self.engaged},
                       "battery": {"percent": 81.0, "voltage": None}, "position": self.position,
                       "alerts": self.alerts[0], "alerts_i18n": self.alerts[1]}
            self.publisher.put(signing.signed_summary(KEY, "fleet", "alpha", seq, summary))

    def close(self) -> None:
        if self.done.is_set():
            return
        self.done.set()
        self.thread.join(5)
        for declared in (self.publisher, self.queryable, self.token):
            declared.undeclare()
        self.session.close()


@pytest.fixture
def hub(app_factory, tmp_path):
    key = tmp_path / "fleet.key"
    key.write_bytes(KEY)
    key.chmod(0o600)
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    app = app_factory(ROVER_WEB_HUB=True, ROVER_WEB_ZENOH_MODE="peer", ROVER_WEB_ZENOH_LISTEN=[endpoint],
                      ROVER_WEB_FLEET_KEY_FILE=str(key))
    server = make_server("127.0.0.1", 0, app, threaded=True)
    thread = threading.Thread(target=server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
    thread.start()
    robot = LightRobot(endpoint)
    yield f"http://127.0.0.1:{server.server_port}", robot
    robot.close()
    server.shutdown()
    server.server_close()


@pytest.fixture
def strict_page(browser):
    """A page with the app's Content-Security-Policy enforced (the shared `page` bypasses it)."""
    from tests.browser.test_csp import RECORD_VIOLATIONS
    from tests.conftest import PageWatch

    context = browser.new_context(viewport={"width": 1280, "height": 900})
    context.add_init_script(RECORD_VIOLATIONS)
    page = context.new_page()
    page.watch = PageWatch(page)
    yield page
    context.close()


def test_the_hub_page_shows_a_robot_heard_and_the_answers_of_stop_all(hub, strict_page):
    url, robot = hub
    page = strict_page
    page.goto(url + "/robots")
    row = page.locator("#hub-table tr[data-robot='alpha'][data-heard='live']")
    row.wait_for(timeout=10000)  # from the template, or added by the page's poll without a reload
    assert row.locator("a").get_attribute("href") == ALPHA_URL
    assert "81%" in row.inner_text()
    page.click("#hub-stop-all")
    page.locator("#hub-last-stop li[data-robot='alpha']", has_text="alpha: engaged").wait_for(timeout=10000)
    assert robot.engaged
    page.locator("#hub-table tr[data-robot='alpha']", has_text="engaged").wait_for(timeout=5000)
    assert page.watch.console_errors == [] and page.watch.offhost == []
    assert page.evaluate("window.__csp") == []


def test_the_hub_has_the_display_menu_its_theme_and_language_kept(hub, strict_page, app_factory):
    """The fleet's page is read in the sun too: the same Display menu as a robot's pages, kept the same way;
    a robot's alerts in the page's language, drawn by the server and then by the page."""
    url, robot = hub
    line = breach_alerts(app_factory())  # a real robot's summary while outside its geofence
    robot.alerts = (line["alerts"], line["alerts_i18n"])
    page = strict_page
    page.goto(url + "/robots")
    page.locator("#hub-table tr[data-robot='alpha']").wait_for(timeout=10000)
    page.locator("#display-menu > summary").click()
    page.locator("#display-theme").select_option("daylight")
    assert page.evaluate("document.documentElement.dataset.theme") == "daylight"
    assert page.evaluate("getComputedStyle(document.body).backgroundColor") == "rgb(238, 241, 244)"
    page.locator("#display-language").select_option("es")
    with page.expect_navigation() as navigation:
        page.locator("#display-language").press("Enter")
    assert page.evaluate("[document.documentElement.lang, document.documentElement.dataset.theme]") == [
        "es", "daylight"]
    assert page.locator("#hub-stop-all").inner_text() == "Parar todo"
    row = page.locator("#hub-table tr[data-robot='alpha']")
    row.wait_for(timeout=10000)
    assert "el robot salió de la geovalla" in navigation.value.text()  # the server's rendering
    # No English left on the page as its scripts drew it (the robot pages' check, tests/browser/test_languages.py).
    page.wait_for_timeout(500)
    assert leftovers(page.evaluate(READ_TEXT, NOT_INTERFACE), english_patterns("es")) == []
    # The page's own drawing: its filter finds the robot by the translated alert's words.
    page.fill("#hub-filter", "zona prohibida")
    page.locator("#hub-table tr[data-robot='alpha']", has_text="zona prohibida 'dock'").wait_for(timeout=10000)
    assert "left the geofence" not in row.inner_text()
    page.fill("#hub-filter", "")
    # The audit every robot page passes (tests/browser/test_a11y_audit.py), in both themes and sizes.
    page.add_script_tag(url=url + AXE_URL)
    found = {}
    for theme in THEMES:
        page.locator("#display-menu > summary").click()
        page.locator("#display-theme").select_option(theme)
        page.locator("#display-menu > summary").click()
        for size in SIZES:
            violations = audit(page, size)
            if violations:
                found[f"{theme} {size}"] = violations
        page.set_viewport_size(SIZES["desktop"])
    assert found == {}, json.dumps(found, indent=1)
    assert page.watch.console_errors == [] and page.evaluate("window.__csp") == []


def test_the_hub_map_shows_a_robot_where_it_is_links_it_and_dims_it_once_lost(hub, strict_page):
    url, robot = hub
    page = strict_page
    page.goto(url + "/robots")
    page.wait_for_selector("#hub-map[data-ready='yes']", timeout=10000)
    assert page.locator(".fleet-marker").count() == 0  # no position yet: no marker, never one at 0,0
    robot.position = ALPHA_AT  # as if its GPS got a fix: the page's poll places it, without a reload
    marker = page.locator(".fleet-marker[data-robot='alpha'][data-heard='live']")
    marker.wait_for(timeout=5000)
    assert float(marker.get_attribute("data-lng")) == pytest.approx(ALPHA_AT["lng"])
    assert float(marker.get_attribute("data-lat")) == pytest.approx(ALPHA_AT["lat"])
    assert marker.inner_text() == "Alpha"
    assert marker.get_attribute("data-url") == ALPHA_URL
    assert marker.is_visible()  # framed on the robot

    # Lost (its Zenoh session ends): kept where it was last seen, dimmed.
    robot.close()
    lost = page.locator(".fleet-marker[data-robot='alpha'][data-heard='lost']")
    lost.wait_for(timeout=5000)
    dot = "getComputedStyle(document.querySelector('.fleet-marker .fleet-marker-dot')).opacity"
    assert float(page.evaluate(dot)) < 1
    assert float(lost.get_attribute("data-lat")) == pytest.approx(ALPHA_AT["lat"])

    assert page.evaluate("window.__csp") == []
    # A marker opens its robot's own rover_web (answered here: nothing listens on port 9).
    page.route(ALPHA_URL, lambda route: route.fulfill(status=200, content_type="text/html", body="alpha"))
    with page.expect_navigation():
        lost.click()
    assert page.url == ALPHA_URL
    assert page.watch.console_errors == [] and page.watch.offhost == []


class Crowd:
    """Robots r00..r{n-1} of fleet `fleet` from one Zenoh session (a token and a summary each, every
    0.5 s), half of them at one spot, the others 40 m apart on a line: the page must keep every marker
    visible and the table usable."""

    def __init__(self, endpoint: str, n: int):
        import zenoh

        config = zenoh.Config()
        config.insert_json5("mode", '"client"')
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        self.session = zenoh.open(config)
        self.names = [f"r{i:02d}" for i in range(n)]
        self.tokens = [self.session.liveliness().declare_token(f"rover_web/fleet/{name}/alive") for name in self.names]
        self.publishers = {name: self.session.declare_publisher(f"rover_web/fleet/{name}/summary")
                           for name in self.names}
        self.done = threading.Event()
        self.thread = threading.Thread(target=self._publish, daemon=True)
        self.thread.start()

    def _publish(self) -> None:
        seq = 0
        while True:
            seq += 1
            for i, name in enumerate(self.names):
                position = ALPHA_AT if i % 2 else {"lng": ALPHA_AT["lng"] + 0.0004 * i, "lat": ALPHA_AT["lat"]}
                summary = {"title": name, "url": None, "link": "ok", "mode": "idle", "estop": {"engaged": False},
                           "battery": {"percent": 90.0 - i / 2, "voltage": None}, "position": position, "alerts": []}
                self.publishers[name].put(signing.signed_summary(KEY, "fleet", name, seq, summary))
            if self.done.wait(0.5):
                return

    def close(self) -> None:
        self.done.set()
        self.thread.join(5)
        for declared in (*self.publishers.values(), *self.tokens):
            declared.undeclare()
        self.session.close()


def test_a_hundred_robots_a_sortable_filterable_table_markers_apart_and_a_robot_s_history(hub, strict_page):
    url, robot = hub
    crowd = Crowd(robot.endpoint, 100)
    page = strict_page
    try:
        page.goto(url + "/robots")
        page.wait_for_function(
            "() => document.querySelectorAll('#hub-table tbody tr[data-heard=\"live\"]').length === 101",
            timeout=15000)
        assert "101 robots: 101 live, 0 waiting, 0 lost" in page.inner_text("#hub-counts")
        # Sorted by battery: r99 (40.5 %) first, then ascending; again: descending.
        page.click("button.hub-sort[data-sort='battery']")
        page.wait_for_function("() => document.querySelector('#hub-table tbody tr').dataset.robot === 'r99'")
        page.click("button.hub-sort[data-sort='battery']")
        page.wait_for_function("() => document.querySelector('#hub-table tbody tr').dataset.robot === 'r00'")
        assert page.get_attribute("#hub-table th:has(button[data-sort='battery'])", "aria-sort") == "descending"
        page.fill("#hub-filter", "r07")
        page.wait_for_function("() => document.querySelectorAll('#hub-table tbody tr').length === 1")
        assert page.locator("#hub-table tbody tr").get_attribute("data-robot") == "r07"
        assert "1 shown" in page.inner_text("#hub-counts")
        # Markers: 50 robots share one spot, and not one dot hides another.
        page.wait_for_selector("#hub-map[data-ready='yes']", timeout=10000)
        page.wait_for_function("() => document.querySelectorAll('.fleet-marker').length === 100", timeout=10000)
        assert "fleet-crowded" in page.get_attribute("#hub-map", "class")
        boxes = page.evaluate("""() => [...document.querySelectorAll('.fleet-marker-dot')]
            .map((d) => d.getBoundingClientRect()).map((r) => [r.x, r.y, r.width, r.height])""")
        overlaps = [(a, b) for i, a in enumerate(boxes) for b in boxes[i + 1:]
                    if a[0] < b[0] + b[2] and b[0] < a[0] + a[2] and a[1] < b[1] + b[3] and b[1] < a[1] + a[3]]
        assert overlaps == []
        # A robot's history: its state changes, newest first.
        page.fill("#hub-filter", "")
        page.click("#hub-table tr[data-robot='r03'] button.hub-history-open")
        page.locator("#hub-history-list li[data-event='live']").wait_for(timeout=5000)
        assert page.text_content("#hub-history-name") == "r03"
        events = page.eval_on_selector_all("#hub-history-list li", "els => els.map((e) => e.dataset.event)")
        assert events[-1] == "found" and "live" in events
        assert page.watch.console_errors == [] and page.watch.offhost == []
        assert page.evaluate("window.__csp") == []
    finally:
        crowd.close()
