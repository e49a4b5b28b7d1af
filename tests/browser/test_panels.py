"""The drone panel in Chromium, driven by the simulated drone in its own process."""

import pytest
from playwright.sync_api import expect

from tests.support.panels_support import drone_sim, post, wait_display, wait_subscribers  # noqa: F401 (fixture)

pytestmark = pytest.mark.browser

WAIT_MS = 15000


def test_buttons_follow_the_drone_unlock_is_required_and_the_log_shows_each_command(live_server, drone_sim, page):  # noqa: F811
    drone_sim("--drone-transition-s", "1.5", "--drone-rate-hz", "10")
    url = live_server.url
    wait_display(url, "drone", "status", "Standby")
    wait_subscribers(url, "drone", {"takeoff": 1, "destination": 1})
    answers = []  # what to answer the next confirmation dialogs; each dialog's text is kept
    dialogs = []

    def on_dialog(dialog):
        dialogs.append(dialog.message)
        dialog.accept() if answers.pop(0) else dialog.dismiss()

    page.on("dialog", on_dialog)
    page.goto(url + "/panels/drone")
    panel = page.locator('[data-panel="drone"]')
    status = panel.locator('[data-display="status"] .cp-text')
    button = lambda cid: panel.locator(f'button[data-control="{cid}"]')  # noqa: E731
    log_rows = panel.locator("[data-log] tr")
    page.wait_for_selector("#link-server[data-state='live']", timeout=WAIT_MS)
    expect(status).to_have_text("Standby")
    expect(panel.locator(".cp-light")).to_have_attribute("data-light", "green")

    # Locked: every command is disabled, and the server refuses one sent around the page.
    expect(panel.locator(".cp-lock-state")).to_have_text("Locked")
    for cid in ("takeoff", "return", "destination", "stop", "height"):
        expect(button(cid)).to_be_disabled()
    assert post(url, "drone/takeoff", {"confirmed": True}).status_code == 409
    expect(log_rows.first).to_contain_text("Take off")
    expect(log_rows.first).to_contain_text("refused")
    expect(log_rows.first).to_contain_text("locked")

    panel.locator('button[data-action="unlock"]').click()
    expect(panel.locator(".cp-lock-state")).to_have_text("Unlocked")
    expect(button("takeoff")).to_be_enabled()
    expect(button("stop")).to_be_enabled()
    expect(button("return")).to_be_disabled()
    expect(button("destination")).to_be_disabled()
    expect(log_rows.first).to_contain_text("unlocked")

    # A dismissed confirmation sends nothing.
    answers.append(False)
    button("takeoff").click()
    page.wait_for_timeout(300)
    assert dialogs == ['Send "Take off"?']
    expect(status).to_have_text("Standby")
    expect(log_rows).to_have_count(2)

    # Take off: Flying (everything but Stop disabled, light red), then Hovering.
    answers.append(True)
    button("takeoff").click()
    expect(status).to_have_text("Flying", timeout=WAIT_MS)
    expect(panel.locator(".cp-light")).to_have_attribute("data-light", "red")
    expect(button("takeoff")).to_be_disabled()
    expect(button("return")).to_be_disabled()
    expect(button("stop")).to_be_enabled()
    expect(log_rows.first).to_contain_text("Take off")
    expect(log_rows.first).to_contain_text("sent")
    expect(status).to_have_text("Hovering", timeout=WAIT_MS)
    expect(button("return")).to_be_enabled()
    expect(button("takeoff")).to_be_disabled()

    # Start needs a valid destination.
    destination = panel.locator('[data-input="destination"]')
    expect(button("destination")).to_be_disabled()
    destination.fill("200")
    expect(button("destination")).to_be_disabled()
    destination.fill("3")
    expect(button("destination")).to_be_enabled()
    answers.append(True)
    button("destination").click()
    expect(status).to_have_text("Flying", timeout=WAIT_MS)
    assert dialogs[-1] == 'Send "Destination (AprilTag id): 3"?'
    expect(log_rows.first).to_contain_text("Destination (AprilTag id)")
    expect(log_rows.first.locator(".cp-value")).to_have_text("3")
    expect(status).to_have_text("Hovering", timeout=WAIT_MS)
    expect(panel.locator('[data-display="tag"] .cp-text')).to_have_text("3")

    # Return: back to Standby on the pad, light green, Take off enabled again.
    answers.append(True)
    button("return").click()
    expect(status).to_have_text("Standby", timeout=WAIT_MS)
    expect(panel.locator(".cp-light")).to_have_attribute("data-light", "green")
    expect(button("takeoff")).to_be_enabled()

    # Stop needs no confirmation; then lock again.
    button("stop").click()
    expect(log_rows.first).to_contain_text("Stop")
    panel.locator('button[data-action="lock"]').click()
    expect(panel.locator(".cp-lock-state")).to_have_text("Locked")
    expect(button("takeoff")).to_be_disabled()
    expect(button("stop")).to_be_disabled()

    rows = [(r.locator("td").nth(1).inner_text(), r.locator(".cp-result").inner_text()) for r in log_rows.all()]
    assert rows == [("Lock", "locked"), ("Stop", "sent"), ("Return", "sent"), ("Destination (AprilTag id)", "sent"),
                    ("Take off", "sent"), ("Unlock", "unlocked"), ("Take off", "refused")]
    assert wait_display(url, "drone", "status", "Standby")
    assert page.watch.offhost == []
    assert page.watch.console_errors == []


def test_a_reloaded_page_shows_the_state_and_log_before_any_event(live_server, page):
    url = live_server.url
    assert post(url, "drone/unlock").status_code == 200
    assert post(url, "drone/stop").status_code == 200
    page.route("**/api/events*", lambda route: route.abort())  # no live events at all
    page.goto(url + "/panels/drone")
    panel = page.locator('[data-panel="drone"]')
    expect(panel.locator(".cp-lock-state")).to_have_text("Unlocked")
    expect(panel.locator('button[data-control="stop"]')).to_be_enabled()
    expect(panel.locator('button[data-control="takeoff"]')).to_be_disabled()  # no status heard
    expect(panel.locator("[data-log] tr").first).to_contain_text("Stop")


def test_the_dashboard_summarises_the_panel(live_server, drone_sim, page):  # noqa: F811
    drone_sim("--drone-transition-s", "1.0")
    wait_display(live_server.url, "drone", "status", "Standby")
    page.goto(live_server.url + "/")
    summary = page.locator('[data-panel-summary="drone"]')
    expect(summary.locator('[data-display="status"] .cp-text')).to_have_text("Standby", timeout=WAIT_MS)
    expect(summary.locator(".cp-light")).to_have_attribute("data-light", "green")
    page.locator("nav a", has_text="Panels").click()
    expect(page).to_have_url(live_server.url + "/panels")
    expect(page.locator('[data-panel="drone"]')).to_be_visible()
    assert page.watch.console_errors == []
