"""The fleet hub's page in Chromium: a robot heard over real Zenoh appears, and "Stop all" shows
its answer. The robot here is a light one in this process (a Zenoh session with a token, signed
summaries and a stop queryable, as bench/hub.py's); tests/integration/hub has real rover_webs."""

from __future__ import annotations

import json
import threading

import pytest
from werkzeug.serving import make_server

from rover_web.zenoh_link import signing
from tests.conftest import free_port

pytestmark = pytest.mark.browser

KEY = b"k" * 64


class LightRobot:
    """alpha of fleet `fleet`: summaries every 0.3 s until closed; engaged once a stop checks."""

    def __init__(self, endpoint: str):
        import zenoh

        config = zenoh.Config()
        config.insert_json5("mode", '"client"')
        config.insert_json5("scouting/multicast/enabled", "false")
        config.insert_json5("connect/endpoints", json.dumps([endpoint]))
        self.session = zenoh.open(config)
        self.engaged = False
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
            summary = {"title": "Alpha", "url": "http://127.0.0.1:9/robots/alpha/", "link": "ok",
                       "mode": "estop" if self.engaged else "idle", "estop": {"engaged": self.engaged},
                       "battery": {"percent": 81.0, "voltage": None}, "position": None, "alerts": []}
            self.publisher.put(signing.signed_summary(KEY, "fleet", "alpha", seq, summary))

    def close(self) -> None:
        self.done.set()
        self.thread.join(5)
        for declared in (self.publisher, self.queryable, self.token):
            declared.undeclare()
        self.session.close()


@pytest.fixture
def hub(app_factory, tmp_path):
    key = tmp_path / "fleet.key"
    key.write_bytes(KEY)
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
    from tests.conftest import PageWatch

    context = browser.new_context(viewport={"width": 1280, "height": 900})
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
    assert row.locator("a").get_attribute("href") == "http://127.0.0.1:9/robots/alpha/"
    assert "81 %" in row.inner_text()
    page.click("#hub-stop-all")
    page.locator("#hub-last-stop li[data-robot='alpha']", has_text="alpha: engaged").wait_for(timeout=10000)
    assert robot.engaged
    page.locator("#hub-table tr[data-robot='alpha']", has_text="engaged").wait_for(timeout=5000)
    assert page.watch.console_errors == [] and page.watch.offhost == []
