"""The e-stop in Chromium: it stops a driving page, and a key held through the release does not
drive until it is released and pressed again."""

import time

import pytest
import requests

from tests.support.teleop_support import is_zero, subscribe_cmd_vel, twists, warm_up

pytestmark = pytest.mark.browser


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
