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
        # Sections start closed (over 120 operations open at once did not render): every tag is
        # listed, and each section, opened on its own, shows every operation of its tag.
        by_tag = {}
        for item in document["paths"].values():
            for op in item.values():
                for tag in op.get("tags", []):
                    by_tag[tag] = by_tag.get(tag, 0) + 1
        page.wait_for_selector(".opblock-tag", timeout=15000)
        shown = page.evaluate("[...document.querySelectorAll('.opblock-tag')].map(t => t.dataset.tag)")
        assert sorted(shown) == sorted(by_tag)
        rendered = 0
        for tag, count in by_tag.items():
            header = page.locator(f".opblock-tag[data-tag='{tag}']")
            header.click()
            section = page.locator(f".opblock-tag-section:has(.opblock-tag[data-tag='{tag}']) .opblock-summary-path")
            page.wait_for_function("([t, n]) => document.querySelectorAll("
                                   "`#operations-tag-${t} ~ div .opblock-summary-path, "
                                   ".opblock-tag-section.is-open .opblock-summary-path`).length >= n",
                                   arg=[tag, count], timeout=15000)
            rendered += section.count()
            if tag == "estop":
                assert page.locator(".opblock-summary-path[data-path='/api/estop']").count() == 2
                assert page.locator(".opblock-post .opblock-summary-path[data-path='/api/estop']").count() == 1
            header.click()  # closed again: one section open at a time
        assert rendered == expected
        refused = [m for m in watch.console_errors if "Content Security Policy" in m or "Refused to" in m]
        assert refused == [], refused
        assert watch.console_errors == [], watch.console_errors
        assert watch.offhost == []
    finally:
        context.close()
