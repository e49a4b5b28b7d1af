"""Pages for the unexpected, in Chromium: an unknown page or map is a 404 page of the app (its bar,
its e-stop, where to go), the API's 404 stays JSON, /login says when sign-in is off, a refused
sign-in keeps where it was going, and the ROS page says what to do when nothing offers a service."""

import pytest
import requests

from tests.support.auth import PASSWORD

pytestmark = pytest.mark.browser


@pytest.mark.parametrize("path,why", [
    ("/no-such-page", "There is no page at /no-such-page."),
    ("/livemap/no-such-map", "There is no map named 'no-such-map'."),
])
def test_an_unknown_page_or_map_is_a_404_page_with_the_apps_bar(live_server, page, path, why):
    answer = page.goto(live_server.url + path)
    assert answer.status == 404
    assert answer.headers["content-type"].startswith("text/html")
    assert page.locator("#not-found-why").inner_text() == why
    assert page.locator("#estop-engage").is_visible()
    page.wait_for_selector("#link-server[data-state='live']", timeout=10000)  # a live page like any other
    hrefs = page.locator("#not-found a").evaluate_all("as => as.map(a => a.getAttribute('href'))")
    assert hrefs == [href for _, href in live_server.rover.nav_links]
    with page.expect_navigation():
        page.locator("#not-found a", has_text="Diagnostics").click()
    assert page.url == live_server.url + "/diagnostics"
    # The browser logs the page's own 404 status; nothing else went wrong.
    assert [e for e in page.watch.console_errors if "status of 404" not in e] == []


def test_the_apis_404_stays_json(live_server):
    answer = requests.get(live_server.url + "/api/no-such-thing", timeout=5)
    assert answer.status_code == 404 and answer.json()["error"] == "not_found"
    answer = requests.get(live_server.url + "/no-such-page", headers={"Accept": "application/json"}, timeout=5)
    assert answer.status_code == 404 and answer.json()["error"] == "not_found"


def test_the_sign_in_page_says_when_sign_in_is_off(live_server, page):
    page.goto(live_server.url + "/login?next=/logs")
    assert "Sign-in is off" in page.locator("#sign-in-off").inner_text()
    assert page.locator("input[name=password]").count() == 0  # nothing to fill in
    with page.expect_navigation():
        page.locator("#sign-in-off a").click()
    assert page.url == live_server.url + "/logs"


def test_a_refused_sign_in_keeps_where_it_was_going(signed_server, page):
    page.goto(signed_server.url + "/diagnostics")
    page.wait_for_url("**/login?next=/diagnostics", wait_until="commit")
    page.fill("input[name=username]", "operator")
    page.fill("input[name=password]", "wrong password")
    page.click("button[type=submit]")
    page.wait_for_selector(".login-error")
    assert page.url.endswith("/login?next=/diagnostics")  # a reload still knows
    page.reload()
    page.fill("input[name=username]", "operator")
    page.fill("input[name=password]", PASSWORD)
    page.click("button[type=submit]")
    page.wait_for_url("**/diagnostics", wait_until="commit")
    assert page.url == signed_server.url + "/diagnostics"


def test_the_ros_page_says_what_to_do_when_no_node_offers_a_service_or_an_action(live_server, page):
    page.goto(live_server.url + "/ros")
    assert "No service to call yet" in page.locator("#ros-services-empty").inner_text()
    assert "No action server" in page.locator("#ros-actions-empty").inner_text()
    assert page.locator(".ros-service").count() == 0
