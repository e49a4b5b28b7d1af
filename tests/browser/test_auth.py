"""Sign-in in a real Chromium: the form, sign-out, a viewer's read-only dashboard, an operator
driving the simulated rover, and the whole dashboard over HTTPS with a self-signed certificate."""

import sys

import pytest
from playwright.sync_api import TimeoutError as PlaywrightTimeout

from rover_web.auth.tls import write_self_signed
from rover_web.estop import EStopService
from rover_web.teleop.service import TeleopService
from tests.conftest import PageWatch, free_port
from tests.support.auth import PASSWORD, add_users
from tests.support.teleop_support import subscribe_cmd_vel, warm_up

pytestmark = pytest.mark.browser


def sign_in(page, base_url, name, password=PASSWORD):
    page.goto(base_url + "/")
    page.wait_for_url("**/login?next=/**", wait_until="commit")
    page.fill("input[name=username]", name)
    page.fill("input[name=password]", password)
    page.click("button[type=submit]")
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)


def test_sign_in_and_sign_out(signed_server, page):
    page.goto(signed_server.url + "/livemap")
    assert "/login" in page.url
    page.fill("input[name=username]", "operator")
    page.fill("input[name=password]", "wrong password")
    page.click("button[type=submit]")
    assert "wrong user name or password" in page.locator(".login-error").inner_text()
    page.fill("input[name=password]", PASSWORD)
    page.click("button[type=submit]")
    page.wait_for_url("**/livemap/**", wait_until="commit")  # /livemap goes on to the default map
    assert "operator" in page.locator(".whoami").text_content()
    # The bar fits itself as the page and its pills fill in (and closes its menu when it refits): the
    # user may be in the bar or in the menu, so open the menu whenever it is closed until the click lands.
    sign_out = page.locator(".whoami button")
    for attempt in range(20):
        menu = page.locator("#topbar-menu")
        if not sign_out.is_visible() and menu.is_visible() and menu.get_attribute("open") is None:
            page.click("#topbar-menu > summary")
        try:
            sign_out.click(timeout=1000)
            break
        except PlaywrightTimeout:
            assert attempt < 19, "Sign out never became clickable"
    page.wait_for_url("**/login", wait_until="commit")
    page.goto(signed_server.url + "/")
    assert "/login" in page.url


def test_a_viewer_sees_a_read_only_dashboard_and_may_still_stop_the_robot(signed_server, page):
    sign_in(page, signed_server.url, "viewer")
    assert page.locator("#teleop-card").get_attribute("data-mode") == "read-only"
    assert "driving needs the operator role" in page.locator("#teleop-message").inner_text()
    assert page.locator("#readonly-banner").is_visible()
    send = page.locator("#wp-send")
    assert send.is_disabled() and "operator role" in send.get_attribute("title")
    assert page.locator("#estop-release").is_disabled()
    page.click("#estop-engage")
    page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=5000)
    assert signed_server.rover.feature(EStopService).engaged
    assert signed_server.rover.feature(EStopService).state()["by"] == "viewer"
    assert page.watch.console_errors == [], page.watch.console_errors


def test_an_operator_drives_the_simulated_rover(signed_server, page, ros_peer, sim_process):
    sim_process()
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    warm_up(peer, signed_server.url, headers={"Authorization": f"Bearer {signed_server.tokens['operator']}"})
    sign_in(page, signed_server.url, "operator")
    page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)
    assert "operator" in page.locator("#teleop-link").inner_text()
    page.keyboard.down("KeyW")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
    page.wait_for_function("Number(document.getElementById('odom-linear').textContent) > 0.5", timeout=10000)
    page.keyboard.up("KeyW")
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 0.0, timeout=2)
    assert signed_server.rover.feature(TeleopService).controller.state()["last_stop"] is not None


def test_the_whole_dashboard_over_https_with_a_self_signed_certificate(server_process, browser, tmp_path, ros_peer):
    cert, key = write_self_signed(tmp_path / "tls", ["127.0.0.1"])
    db_path = tmp_path / "https.sqlite3"
    add_users(db_path, "operator")
    port = free_port()
    server = server_process(port=port, scheme="https", ca=cert.parent / "ca.pem", env={
        "ROVER_WEB_AUTH": "required", "ROVER_WEB_DB_PATH": str(db_path)},
        args=[sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload", "--host", "127.0.0.1",
              "--port", str(port), "--cert", str(cert), "--key", str(key)]).start()
    peer = ros_peer()
    subscribe_cmd_vel(peer)
    context = browser.new_context(viewport={"width": 1280, "height": 900}, ignore_https_errors=True)
    try:
        page = context.new_page()
        watch = PageWatch(page)
        sign_in(page, server.url, "operator")
        assert page.url.startswith("https://")
        page.wait_for_selector("#teleop-link[data-state='live']", timeout=10000)  # wss:// through TLS
        assert page.evaluate("window.isSecureContext") is True  # what the Gamepad API needs
        page.keyboard.down("KeyW")
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=5)
        page.keyboard.up("KeyW")
        peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 0.0, timeout=2)
        page.click("#estop-engage")
        page.wait_for_selector("#estop[data-engaged='yes'][data-unconfirmed='no']", timeout=5000)
        assert watch.offhost == [] and watch.console_errors == [], (watch.offhost, watch.console_errors)
    finally:
        context.close()



def test_anyone_on_the_sign_in_page_can_engage_the_e_stop_but_not_release_it(signed_server, page):
    import requests

    viewer = {"Authorization": f"Bearer {signed_server.tokens['viewer']}"}
    page.goto(signed_server.url + "/")
    page.wait_for_url("**/login?next=/**", wait_until="commit")
    page.click("#login-estop")
    page.wait_for_selector(".login-estop-notice")
    assert "E-stop engaged on every robot" in page.locator(".login-estop-notice").inner_text()
    state = requests.get(signed_server.url + "/api/estop", headers=viewer, timeout=5).json()
    assert state["engaged"] is True and state["by"].startswith("sign-in page")
    # The page still signs in; only an operator's Release lets the robot move again.
    page.fill("input[name=username]", "operator")
    page.fill("input[name=password]", PASSWORD)
    page.click("form.login button[type=submit]")
    page.wait_for_selector("#estop[data-engaged='yes']", timeout=10000)
