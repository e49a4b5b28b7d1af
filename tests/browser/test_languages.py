"""Every page in Spanish and Japanese in Chromium, with no English left; the language a user saved
follows them to another browser from the first byte; Accept-Language picks the page's language.

What counts as "English left": a visible text node, or a title / aria-label / placeholder a person
reads, that is exactly the English of a message id whose translation in that language differs
(the message ids come from the shipped .po files, so a string wrapped but left out of a page, or
drawn in English by a script, is found). Code, keys and data (<code>, <pre>, a topic list) are
not words of the interface and are not read.
"""

from __future__ import annotations

import re

import pytest
import requests

from rover_web.config import ROOT
from rover_web.i18n.catalogues import SAID, read_language, translated
from tests.browser.test_auth import PASSWORD, sign_in

pytestmark = pytest.mark.browser

LANGUAGES = ("es", "ja")
PAGES = ["/", "/status", "/livemap", "/topics", "/panels", "/waypoints", "/logs", "/diagnostics", "/ros", "/robots",
         "/recordings", "/plot", "/tf", "/3d", "/api/docs", "/login", "/no/such/page"]
# Not interface words: code, and data shown as it is (frame ids, topic names, the frame fields of the
# TF lookup, a robot's name: the one robot of a test app is called "robot"); and a mission control
# panel's own labels, which its operator writes in the panel's TOML (docs/panels.md).
NOT_INTERFACE = ", ".join([
    "code", "pre", "kbd", "samp", "script", "style", "select#view3d-fixed", "select#plot-topic", "select#camera-topic",
    "form.tf-lookup input", ".cp-displays dt", ".cp-control", ".cp-input label", "[data-panel-summary] > .muted",
    "[data-panel-summary] > a", ".cp-head h2", "[data-field='name']",
    # The robot's own diagnostic messages (diagnostic_msgs: what the robot says, as it says it), and
    # Swagger UI's tag headings on /api/docs (the API's own identifiers, as codes are).
    "#diag-body td:nth-child(4)", ".opblock-tag",
])

# The page's readable text: visible text nodes and read attributes of visible elements.
READ_TEXT = """(skip) => {
    const out = [];
    const shown = (el) => el && el.checkVisibility({ visibilityProperty: true }) ;
    const walker = document.createTreeWalker(document.body, NodeFilter.SHOW_TEXT);
    for (let n = walker.nextNode(); n; n = walker.nextNode()) {
        const el = n.parentElement;
        const text = n.nodeValue.replace(/\\s+/g, ' ').trim();
        if (!text || el.closest(skip)) continue;
        if (shown(el) || el.closest('option')) out.push(text);
    }
    for (const el of document.querySelectorAll('[title], [aria-label], [placeholder], [alt]')) {
        if (el.closest(skip) || !(shown(el) || el.closest('select'))) continue;
        for (const a of ['title', 'aria-label', 'placeholder', 'alt']) {
            const v = el.getAttribute(a);
            if (v) out.push(v.replace(/\\s+/g, ' ').trim());
        }
    }
    out.push(document.title);
    return out;
}"""


def english_patterns(lang: str, only_browser: bool = False) -> list[tuple[re.Pattern, str]]:
    """Each plain-text message id whose `lang` translation differs, as a whole-text pattern."""
    patterns = []
    for message in read_language(ROOT / "translations" / lang, lang):
        if not message.id or not translated(message):
            continue
        if only_browser and SAID not in message.flags \
                and not any(path.startswith("static/js/") for path, _ in message.locations):
            continue  # the browser's: the code's own words, and the sentences the server says (events.po)
        ids = message.id if isinstance(message.id, tuple) else (message.id,)
        strings = message.string if isinstance(message.string, tuple) else (message.string,)
        for msgid in ids:
            if "<" in msgid or msgid in strings:
                continue  # markup is split across nodes; a word kept the same is no leftover
            body = re.sub(r"\\%\\((\w+)\\)[sd]", ".+", re.escape(re.sub(r"\s+", " ", msgid)))
            patterns.append((re.compile(body.replace("%%", "%")), msgid))
    return patterns


def leftovers(texts: list[str], patterns) -> list[str]:
    return sorted({f"{text!r} (msgid {msgid!r})" for text in texts for pattern, msgid in patterns
                   if pattern.fullmatch(text)})


def context_in(browser, lang: str | None, base_url: str, **options):
    context = browser.new_context(viewport={"width": 1280, "height": 900}, **options)
    if lang:
        context.add_cookies([{"name": "rover_web_lang", "value": lang, "url": base_url}])
    return context


@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_page_as_the_server_draws_it_has_no_english_left(live_server, browser, lang):
    """Scripts off: exactly what the server renders (the pages, the sign-in page, the 404 and, posted
    as a plain form, the e-stop's engaged page with the banner on every page after it)."""
    patterns = english_patterns(lang)
    assert len(patterns) > 300  # the catalogue is read: a broken reader must not pass this test empty
    context = context_in(browser, lang, live_server.url, java_script_enabled=False)
    found = {}
    try:
        page = context.new_page()
        for path in PAGES:
            page.goto(live_server.url + path)
            assert page.locator("html").get_attribute("lang") == lang, path
            found[path] = leftovers(page.evaluate(READ_TEXT, NOT_INTERFACE), patterns)
        page.goto(live_server.url + "/")
        page.click("#estop-engage")  # the header's E-STOP as a plain form: the engaged page
        page.wait_for_selector("#estop-engaged-page")
        for path in (page.url.removeprefix(live_server.url), "/livemap", "/"):
            if path != page.url.removeprefix(live_server.url):
                page.goto(live_server.url + path)
            found[f"{path} (e-stop engaged)"] = leftovers(page.evaluate(READ_TEXT, NOT_INTERFACE), patterns)
    finally:
        context.close()
        requests.post(live_server.url + "/api/estop", json={"engaged": False}, timeout=5)
    assert {path: words for path, words in found.items() if words} == {}


@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_live_page_has_no_english_from_the_browser_code(live_server, browser, sim_process, lang):
    """Scripts on, the robot simulated: what the browser code writes is in the language too (the
    entries of the catalogue located in static/js: what static/js/core/i18n.js translates)."""
    patterns = english_patterns(lang, only_browser=True)
    if not patterns:
        pytest.skip("no browser-code message in the catalogue yet (translations/*/LC_MESSAGES/browser.po)")
    sim_process()
    context = context_in(browser, lang, live_server.url, bypass_csp=True)
    found = {}
    try:
        page = context.new_page()
        for path in PAGES:
            page.goto(live_server.url + path)
            if path not in ("/api/docs", "/login"):
                page.wait_for_selector("body[data-link='up']", timeout=15000)
            page.wait_for_load_state("networkidle")
            page.wait_for_timeout(500)  # a status period: what the first events write is on the page
            found[path] = leftovers(page.evaluate(READ_TEXT, NOT_INTERFACE), patterns)
    finally:
        context.close()
    assert {path: words for path, words in found.items() if words} == {}


def test_a_users_language_follows_them_to_another_browser_from_the_first_byte(signed_server, browser):
    first = context_in(browser, None, signed_server.url, locale="en-US", bypass_csp=True)
    try:
        page = first.new_page()
        sign_in(page, signed_server.url, "viewer")
        status = page.evaluate("""url => fetch(url, {method: 'PUT', headers: {'Content-Type': 'application/json'},
                                                     body: JSON.stringify({language: 'ja'})}).then(r => r.status)""",
                               signed_server.url + "/api/me/preferences")
        assert status == 200
    finally:
        first.close()
    # Another browser, English by its Accept-Language and without the cookie: English until the
    # user signs in, Japanese in the very page the sign-in leads to.
    second = context_in(browser, None, signed_server.url, locale="en-US")
    try:
        page = second.new_page()
        page.goto(signed_server.url + "/login")
        assert page.locator("html").get_attribute("lang") == "en"
        assert page.locator("form.login button[type=submit]").inner_text() == "Sign in"
        page.fill("input[name=username]", "viewer")
        page.fill("input[name=password]", PASSWORD)
        with page.expect_response(lambda r: r.url.rstrip("/") == signed_server.url and r.request.method == "GET") \
                as answer:
            page.click("button[type=submit]")
        first_byte = answer.value.text()
        assert re.search(r'<html lang="ja" data-theme="[a-z]+" '
                         r'data-catalogue="[^"]+/i18n/ja\.[0-9a-f]{12}\.json">', first_byte)
        assert ">ダッシュボード<" in first_byte and ">Dashboard<" not in first_byte
        assert page.locator("html").get_attribute("lang") == "ja"
    finally:
        second.close()


def test_the_browsers_language_picks_the_page_language_and_a_bad_cookie_is_ignored(live_server, browser):
    for locale, lang in (("es-MX", "es"), ("ja-JP", "ja"), ("fr-FR", "en"), ("en-GB", "en")):
        context = browser.new_context(locale=locale, java_script_enabled=False)
        context.add_cookies([{"name": "rover_web_lang", "value": "xx", "url": live_server.url}])
        try:
            page = context.new_page()
            page.goto(live_server.url + "/status")
            assert page.locator("html").get_attribute("lang") == lang, locale
            assert page.locator("#topbar .nav a[href$='/status']").inner_text() == \
                {"es": "Estado", "ja": "ステータス", "en": "Status"}[lang]
        finally:
            context.close()
