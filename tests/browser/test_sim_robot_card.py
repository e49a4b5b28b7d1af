"""The demo's Robot card reads the simulated battery: a real "% · V" live in Chromium, not "— % · — V"."""

import pytest

pytestmark = [pytest.mark.browser, pytest.mark.ros]


def test_the_robot_card_shows_the_simulated_battery(live_server, sim_process, page):
    page.goto(live_server.url + "/")
    assert page.inner_text("#odom-battery-percent") == "—"  # nothing published yet
    sim_process("--only", "rover", "--battery", "64")
    page.wait_for_function("document.getElementById('odom-battery-percent').textContent === '64'", timeout=20000)
    volts = float(page.inner_text("#odom-battery-voltage"))
    assert 22.0 < volts < 23.5  # six Li-ion cells at 64 %, at rest
    assert page.get_attribute("#odom-battery", "title").endswith(": discharging")
    page.reload()  # and the page as the server renders it, before any event
    assert page.inner_text("#odom-battery-percent") == "64"
    assert page.watch.console_errors == [] and page.watch.offhost == []
