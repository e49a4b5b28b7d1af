"""/api/docs renders every operation of /api/openapi.json from vendored files, under the enforced CSP."""

import pytest
import requests

from tests.conftest import PageWatch

pytestmark = pytest.mark.browser


def test_the_api_page_renders_every_operation_under_the_policy(live_server, browser):
    document = requests.get(live_server.url + "/api/openapi.json", timeout=5).json()
    expected = sum(len(item) for item in document["paths"].values())
    context = browser.new_context(viewport={"width": 1280, "height": 900})  # bypass_csp stays off
    try:
        page = context.new_page()
        watch = PageWatch(page)
        response = page.goto(live_server.url + "/api/docs")
        assert "script-src 'self'" in response.headers["content-security-policy"]
        page.wait_for_selector(".opblock-summary-path", timeout=15000)
        paths = page.locator(".opblock .opblock-summary-path")
        assert paths.count() == expected
        assert page.locator(".opblock-summary-path[data-path='/api/estop']").count() == 2
        assert page.locator(".opblock-post .opblock-summary-path[data-path='/api/estop']").count() == 1
        refused = [m for m in watch.console_errors if "Content Security Policy" in m or "Refused to" in m]
        assert refused == [], refused
        assert watch.console_errors == [], watch.console_errors
        assert watch.offhost == []
    finally:
        context.close()
