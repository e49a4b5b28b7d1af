"""Shared fixtures: a private ROS domain, apps, live servers, ROS peers, SSE clients, Chromium."""

from __future__ import annotations

import os
import random
import re
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from rover_web.config import ROOT


def pytest_configure(config):
    # Every test session gets its own ROS domain on localhost only, so parallel runs and a robot on
    # the same network never see the test traffic. Set before anything initialises rclpy.
    os.environ.setdefault("ROS_DOMAIN_ID", os.environ.get("ROVER_WEB_TEST_DOMAIN_ID") or str(random.randint(1, 200)))
    # Under pytest-xdist the workers inherit the controller's domain; each (gw0, gw1, ...) takes
    # the next one from it, so two workers' peers and servers never meet.
    worker = os.environ.get("PYTEST_XDIST_WORKER")
    if worker:
        base = int(os.environ["ROS_DOMAIN_ID"])
        os.environ["ROS_DOMAIN_ID"] = str((base + int(worker.removeprefix("gw"))) % 200 + 1)
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    os.environ.pop("ROS_STATIC_PEERS", None)
    # Every ROVER_WEB_* name goes, ROVER_WEB_TEST_DOMAIN_ID too (it is used above): the app refuses
    # unknown ROVER_WEB_* settings, in this process and in the servers and simulators tests start.
    for key in [k for k in os.environ if k.startswith("ROVER_WEB_")]:
        del os.environ[key]


def pytest_collection_modifyitems(config, items):
    # Browser tests run last. Playwright's sync API leaves its asyncio loop marked as running on the
    # main thread (and greenlet switches in its frames) until the session ends, so a later test's
    # asyncio.run() fails and ast.parse can raise "AST constructor recursion depth mismatch".
    # The sort is stable, and pytest-xdist hands tests out in this order, so on every worker no
    # other test follows one that started Chromium.
    items.sort(key=lambda item: "browser" in getattr(item, "fixturenames", ()))


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(autouse=True)
def _close_teleop_clients():
    """Teleop test clients a test left open are closed, not left to the garbage collector."""
    yield
    from tests.support.teleop_support import close_open_clients

    close_open_clients()


@pytest.fixture
def app_factory(tmp_path):
    """Make apps with test settings; every app made is shut down at the end of the test."""
    from rover_web import create_app

    made = []

    def make(**settings):
        config = {"TESTING": True, "ROVER_WEB_DB_PATH": str(tmp_path / f"rover_web{len(made)}.sqlite3"),
                  # 32+ bytes (a shorter key is refused), and no key file in the checkout's instance folder
                  "ROVER_WEB_SECRET_KEY": "tests-" + "k" * 32,
                  "ROVER_WEB_HOST": "127.0.0.1",  # where the in-process test servers listen
                  "ROVER_WEB_RECORDINGS_DIR": str(tmp_path / f"recordings{len(made)}")}  # not the checkout's
        config.update(settings)
        app = create_app(config)
        made.append(app)
        return app

    yield make
    for app in made:
        rover = app.extensions.get("rover_web")
        if rover is not None:
            rover.shutdown()


@pytest.fixture
def app(app_factory):
    return app_factory()


@pytest.fixture
def client(app):
    return app.test_client()


class LiveServer:
    """The app served by Werkzeug's threaded server on 127.0.0.1 in this process."""

    def __init__(self, app):
        from werkzeug.serving import make_server

        self.app = app
        self.server = make_server("127.0.0.1", 0, app, threaded=True)
        self.port = self.server.server_port
        self.url = f"http://127.0.0.1:{self.port}"
        self.thread = threading.Thread(target=self.server.serve_forever, kwargs={"poll_interval": 0.05}, daemon=True)
        self.thread.start()

    @property
    def rover(self):
        return self.app.extensions["rover_web"]

    def stop(self) -> None:
        for robot in self.rover.fleet:  # end every robot's open event streams so their threads finish
            robot.hub.close()
        self.server.shutdown()
        self.server.server_close()


@pytest.fixture
def live_server_factory(app_factory):
    servers = []

    def make(**settings):
        server = LiveServer(app_factory(**settings))
        servers.append(server)
        return server

    yield make
    for server in servers:
        server.stop()


@pytest.fixture
def live_server(live_server_factory):
    return live_server_factory()


def _signed_settings(tmp_path) -> tuple[dict, dict]:
    """Sign-in required, and one user per role (named after it) already in the database."""
    from tests.support.auth import add_users

    db_path = tmp_path / "signed.sqlite3"
    tokens = add_users(db_path)
    return {"ROVER_WEB_AUTH": "required", "ROVER_WEB_DB_PATH": str(db_path)}, tokens


@pytest.fixture
def signed_app(app_factory, tmp_path):
    """An app (test client) with sign-in on; `.tokens[role]` is each user's API token."""
    settings, tokens = _signed_settings(tmp_path)
    app = app_factory(**settings)
    app.tokens = tokens
    return app


@pytest.fixture
def signed_server_factory(live_server_factory, tmp_path):
    """make(**settings): a live server with sign-in on and those settings (one per test: the users
    live in one database file); `.tokens[role]` is each user's API token."""
    def make(**extra):
        settings, tokens = _signed_settings(tmp_path)
        server = live_server_factory(**settings, **extra)
        server.tokens = tokens
        return server

    return make


@pytest.fixture
def signed_server(signed_server_factory):
    """A live server with sign-in on; `.tokens[role]` is each user's API token."""
    return signed_server_factory()


class ServerProcess:
    """`flask --app rover_web run --no-reload` in its own process, as an operator starts it."""

    def __init__(self, port: int | None = None, env: dict | None = None, args: list[str] | None = None,
                 scheme: str = "http", ca: str | None = None):
        from tests.support.rospeer import subprocess_env

        self.port = port or free_port()
        self.url = f"{scheme}://127.0.0.1:{self.port}"
        self.verify = str(ca) if ca else True  # the CA an HTTPS server's certificate is checked against
        self.env = subprocess_env(**(env or {}))
        self.args = args
        self.proc = None
        self.log_path = None

    def start(self, timeout: float = 30.0) -> ServerProcess:
        import tempfile

        import requests

        cmd = self.args or [sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                            "--host", "127.0.0.1", "--port", str(self.port)]
        log = tempfile.NamedTemporaryFile(prefix="rover_web-server-", suffix=".log", delete=False)
        self.log_path = log.name
        with log:  # the child has its own descriptor; ours is not needed past the start
            self.proc = subprocess.Popen(cmd, cwd=ROOT, env=self.env, stdout=log, stderr=subprocess.STDOUT)
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"server exited with {self.proc.returncode}:\n{self.log()}")
            try:
                if requests.get(self.url + "/api/status", timeout=1, verify=self.verify).status_code in (200, 401):
                    return self
            except requests.RequestException:
                time.sleep(0.1)
        raise RuntimeError(f"server did not answer within {timeout} s:\n{self.log()}")

    def log(self) -> str:
        return Path(self.log_path).read_text(errors="replace") if self.log_path else ""

    def stop(self, sig=None, timeout: float = 10.0) -> int | None:
        import signal as _signal

        if self.proc is None or self.proc.poll() is not None:
            return self.proc.returncode if self.proc else None
        self.proc.send_signal(sig or _signal.SIGTERM)
        try:
            return self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            return self.proc.wait(5)


@pytest.fixture
def server_process(tmp_path):
    started = []

    def make(port=None, env=None, args=None, scheme="http", ca=None):
        env = dict(env or {})
        env.setdefault("ROVER_WEB_DB_PATH", str(tmp_path / f"server{len(started)}.sqlite3"))
        env.setdefault("ROVER_WEB_RECORDINGS_DIR", str(tmp_path / f"server{len(started)}-recordings"))
        server = ServerProcess(port, env, args, scheme, ca)
        started.append(server)
        return server

    yield make
    for server in started:
        server.stop()


def closing_factory(factory):
    """A fixture's body: make(...) builds with `factory`, and every one made is closed after the test."""
    made = []

    def make(*args, **kwargs):
        thing = factory(*args, **kwargs)
        made.append(thing)
        return thing

    yield make
    for thing in made:
        thing.close()


@pytest.fixture
def ros_peer():
    """make(name): a real ROS node in another process (tests/support/rospeer.py)."""
    from tests.support.rospeer import RosPeer

    yield from closing_factory(lambda name="test_peer": RosPeer(name))


@pytest.fixture
def action_server():
    """make(name): tests/support/peers/action_server.py serving the action `name` in its own process."""
    from tests.support.action_peer import ActionServerPeer

    yield from closing_factory(ActionServerPeer)


SIM_START_S = 60  # a loaded 2-core machine starts one in a few seconds


class SimProcess:
    """`python -m rover_web.sim` (or one part, e.g. module="rover_web.sim.drone") in its own process."""

    def __init__(self, args: list[str], module: str = "rover_web.sim", **env: str):
        """`env`: variables over the test process's ROS environment (another ROS_DOMAIN_ID, say)."""
        from tests.support.rospeer import subprocess_env

        self.proc = subprocess.Popen([sys.executable, "-m", module, *args], cwd=ROOT,
                                     env=subprocess_env(**env), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                     text=True)
        # Fast DDS may log before the ready line (a shared-memory port another process left locked, say):
        # wait for the line itself, for a bounded time; reading "to the end" of a running simulator
        # would wait for ever.
        self.output: list[str] = []
        ready = threading.Event()
        self._drainer = threading.Thread(target=self._drain, args=(ready,), daemon=True)
        self._drainer.start()
        if not ready.wait(SIM_START_S):
            self.proc.kill()
            self.proc.wait(5)
            raise RuntimeError(f"simulator did not start within {SIM_START_S} s: {''.join(self.output)[-2000:]}")

    def _drain(self, ready: threading.Event) -> None:
        for line in self.proc.stdout:
            self.output.append(line)
            if "simulator running" in line:
                ready.set()

    def stop(self) -> int:
        import signal as _signal

        if self.proc.poll() is None:
            self.proc.send_signal(_signal.SIGINT)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
        code = self.proc.wait(5)
        self._drainer.join(5)  # reads to the end of the pipe once the process is gone
        self.proc.stdout.close()
        return code


@pytest.fixture
def sim_process():
    sims = []

    def make(*args: str):
        sim = SimProcess(list(args))
        sims.append(sim)
        return sim

    yield make
    for sim in sims:
        sim.stop()


@pytest.fixture
def sse_client():
    from tests.support.sse import SseClient

    clients = []

    def make(url: str, **kwargs):
        client = SseClient(url, **kwargs)
        clients.append(client)
        return client

    yield make
    for client in clients:
        client.close()


# --- Chromium through Playwright ---

CHROMIUM = os.environ.get("ROVER_WEB_TEST_CHROMIUM", "/usr/bin/chromium")


@pytest.fixture(scope="session")
def browser():
    from playwright.sync_api import sync_playwright

    if not Path(CHROMIUM).exists():
        pytest.fail(f"{CHROMIUM} not found: install Debian's chromium (scripts/test.sh does)")
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=[
            "--no-sandbox", "--disable-gpu", "--enable-unsafe-swiftshader", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-quic"])
        yield browser
        browser.close()


class PageWatch:
    """Every request that would leave 127.0.0.1 is blocked and recorded; console errors are kept."""

    LOCAL_PREFIXES = ("http://127.0.0.1", "http://localhost", "ws://127.0.0.1", "ws://localhost",
                      "https://127.0.0.1", "https://localhost", "wss://127.0.0.1", "wss://localhost",
                      "data:", "blob:", "about:")

    def __init__(self, page):
        self.page = page
        self.offhost: list[str] = []
        self.console_errors: list[str] = []
        page.route("**/*", self._route)
        page.on("console", self._console)
        page.on("pageerror", lambda e: self.console_errors.append(f"pageerror: {e}"))

    # An MJPEG acknowledgement sent as the page leaves can reach the server after its stream has
    # ended, and is answered 404 by design (tests/integration/camera/test_acks.py); the browser logs
    # that answer as an error. Seen once in CI, in a teleop test that navigates away mid-stream.
    ACK_PATH = re.compile(r"/api/camera/viewers/[^/]+/ack$")

    def _console(self, message) -> None:
        if message.type != "error":
            return
        url = (message.location or {}).get("url", "")
        if "status of 404" in message.text and self.ACK_PATH.search(url.split("?")[0]):
            return
        self.console_errors.append(message.text)

    def _route(self, route):
        url = route.request.url
        if url.startswith(self.LOCAL_PREFIXES):
            route.continue_()
        else:
            self.offhost.append(url)
            route.abort()


@pytest.fixture
def page(browser):
    # bypass_csp: Playwright's wait_for_function compiles its predicate in the page, which the
    # app's Content-Security-Policy forbids (no 'unsafe-eval'). tests/browser/test_csp.py loads
    # every page with the policy on and checks that nothing the app itself does is refused.
    # color_scheme: the pages' theme is "auto" unless chosen, and follows it; the tests written
    # before the daylight theme see the dark one they were written for. Daylight is tested on
    # purpose (tests/browser/test_field_a11y.py, test_a11y_audit.py).
    context = browser.new_context(viewport={"width": 1280, "height": 900}, bypass_csp=True, color_scheme="dark")
    pg = context.new_page()
    pg.watch = PageWatch(pg)
    yield pg
    context.close()
