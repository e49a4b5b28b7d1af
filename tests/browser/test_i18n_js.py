"""static/js/core/i18n.js in Chromium (issue 43): the browser code's translations and locale formatting.

A real HTTP server (the standard library's, on 127.0.0.1) serves the repository's own static/js files
and each language's catalogue JSON as the app makes it from the shipped translations/<lang>/LC_MESSAGES/
*.po (rover_web/i18n) and names it on <html data-catalogue>; the pages here set that attribute
themselves, so each case (a missing or a slow catalogue, a bad language tag) is one page. Each imports
the real module: an English page must not fetch anything nor wait, a Spanish or Japanese page shows the
catalogue's words, and a catalogue that cannot be loaded leaves the page working, in English.
(tests/browser/test_i18n_pages.py checks the app's own pages.)
"""

from __future__ import annotations

import json
import threading
import time
from functools import partial
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest

from rover_web.config import ROOT
from rover_web.i18n.catalogues import compile_language
from rover_web.teleop.link import verdict
from rover_web.web.api_messages import Text, with_wire
from tests.support.geofence_helpers import DOCK, breach_at

pytestmark = pytest.mark.browser

SLOW_S = 0.8
HANG_S = 30  # far past i18n.js's CATALOGUE_WAIT_MS (8 s)


def catalogue_json(language: str) -> bytes:
    """The browser's catalogue of one language, exactly as the app serves it (rover_web/i18n)."""
    return compile_language(ROOT / "translations" / language, language).browser


# One page per case: the module under test is imported by the page's own module script, which puts what
# the page computed on window.got (and records when DOMContentLoaded fired against when it ran).
PAGE = """<!doctype html>
<html lang="{lang}"{catalogue}>
<head><meta charset="utf-8"><title>i18n</title></head>
<body>
<p id="word"></p>
<script type="module" src="/probe.js"></script>
<script>window.events = []; document.addEventListener('DOMContentLoaded', () => window.events.push('dcl'));</script>
</body>
</html>
"""

PROBE = """import * as i18n from '/js/core/i18n.js';
window.events.push('module ran');
document.getElementById('word').textContent = i18n._('ENGAGED');
i18n.afterPageScripts(() => window.events.push('after page scripts'));
window.i18n = i18n;
"""


class Handler(SimpleHTTPRequestHandler):
    """static/ as it is on disk, plus the test pages and catalogues; `?slow` answers after SLOW_S."""

    pages: dict[str, bytes] = {}

    def log_message(self, *args) -> None:  # quiet
        pass

    def do_GET(self):  # noqa: N802 (http.server's name)
        path, _, query = self.path.partition("?")
        if "slow" in query:
            time.sleep(SLOW_S)
        if "hang" in query:
            time.sleep(HANG_S)
        if path in self.pages:
            body = self.pages[path]
            kind = "text/html" if path.endswith(".html") else (
                "text/javascript" if path.endswith(".js") else "application/json")
            self.send_response(200)
            self.send_header("Content-Type", f"{kind}; charset=utf-8")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            try:
                self.wfile.write(body)
            except (BrokenPipeError, ConnectionResetError):
                pass  # the page gave up waiting (the hang case)
            return
        self.path = path
        super().do_GET()


@pytest.fixture(scope="module")
def server():
    pages = {"/probe.js": PROBE.encode()}
    for lang in ("es", "ja"):
        pages[f"/catalogue.{lang}.json"] = catalogue_json(lang)
    for name, lang, catalogue in (("en", "en", ""), ("es", "es", "/catalogue.es.json"),
                                  ("ja", "ja", "/catalogue.ja.json"), ("missing", "es", "/catalogue.xx.json"),
                                  ("slow", "es", "/catalogue.es.json?slow=1"),
                                  ("hang", "es", "/catalogue.es.json?hang=1"), ("bad_lang", "not a tag!", "")):
        attr = f' data-catalogue="{catalogue}"' if catalogue else ""
        pages[f"/{name}.html"] = PAGE.format(lang=lang, catalogue=attr).encode()
    Handler.pages = pages
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), partial(Handler, directory=str(Path(ROOT) / "static")))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()
    httpd.server_close()


def open_page(page, server, name):
    requests = []
    page.on("request", lambda r: requests.append(r.url))
    page.goto(f"{server}/{name}.html")
    page.wait_for_function("window.i18n !== undefined && window.events.includes('after page scripts')",
                           timeout=20000)
    return requests


def test_an_english_page_fetches_no_catalogue_and_its_strings_are_the_ids(page, server):
    requests = open_page(page, server, "en")
    assert not [url for url in requests if "catalogue" in url or url.endswith(".json")]
    got = page.evaluate("""() => {
        const { _, ngettext, locale, formatNumber, formatUnit } = window.i18n;
        return {
            locale, word: document.getElementById('word').textContent,
            hello: _('By %(name)s at %(time)s.', { name: 'Ana', time: '10:00' }),
            missing: _('By %(name)s.', {}), percent: _('%(n)d%% sure', { n: 100 }), plain: _('100% sure'),
            one: ngettext('%(num)d pose', '%(num)d poses', 1), many: ngettext('%(num)d pose', '%(num)d poses', 1234),
            fixed: formatNumber(0.25, 2), grouped: formatNumber(1234567.5, 1), metres: formatUnit(0.5, 'm', 2),
            ms: formatUnit(12, 'ms'), hz: formatUnit(9.94, 'Hz', 1), deg: formatUnit(45, '°'), nan: formatNumber(NaN),
        };
    }""")
    assert got == {
        "locale": "en", "word": "ENGAGED", "hello": "By Ana at 10:00.", "missing": "By %(name)s.",
        "percent": "100% sure", "plain": "100% sure", "one": "1 pose", "many": "1,234 poses", "fixed": "0.25",
        "grouped": "1,234,567.5",
        "metres": "0.50 m", "ms": "12 ms", "hz": "9.9 Hz", "deg": "45°", "nan": "–"}
    # Nothing waited: the page's module ran before DOMContentLoaded, as any module without the await.
    assert page.evaluate("window.events")[:2] == ["module ran", "dcl"]


def test_a_spanish_page_shows_the_catalogues_words_numbers_and_plural_forms(page, server):
    requests = open_page(page, server, "es")
    assert sum(url.endswith("/catalogue.es.json") for url in requests) == 1
    got = page.evaluate("""() => {
        const { _, ngettext, locale, formatNumber, formatUnit, formatTime, formatList } = window.i18n;
        return {
            locale, word: document.getElementById('word').textContent,
            sentence: _('By %(name)s at %(time)s.', { name: 'Ana', time: '10:00' }),
            untranslated: _('A message no catalogue has: %(x)s', { x: 1 }),
            one: ngettext('%(num)d pose', '%(num)d poses', 1), two: ngettext('%(num)d pose', '%(num)d poses', 2),
            million: ngettext('%(num)d pose', '%(num)d poses', 1000000),
            english: ngettext('%(num)d thing', '%(num)d things', 1),
            fixed: formatNumber(0.25, 2), metres: formatUnit(0.5, 'm', 2), percent: formatUnit(87, '%', 0),
            pair: _('%(x)s, %(y)s m', { x: formatNumber(1.5, 2), y: formatNumber(-2, 2) }),
            time: formatTime(Date.UTC(2026, 0, 2, 13, 4, 5), { hour: '2-digit', minute: '2-digit', timeZone: 'UTC' }),
            list: formatList(['boat', 'drone', 'sub']),
        };
    }""")
    assert got == {
        "locale": "es", "word": "ACTIVADA", "sentence": "Por Ana a las 10:00.",
        "untranslated": "A message no catalogue has: 1", "one": "1 pose", "two": "2 poses",
        "million": "1.000.000 poses", "english": "1 thing", "fixed": "0,25", "metres": "0,50 m",
        "percent": "87\u00a0%", "pair": "1,50; -2,00 m", "time": "13:04", "list": "boat, drone y sub"}


def test_a_japanese_page_has_one_plural_form(page, server):
    open_page(page, server, "ja")
    got = page.evaluate("""() => {
        const { _, ngettext } = window.i18n;
        return [document.getElementById('word').textContent, ngettext('%(num)d pose', '%(num)d poses', 1),
                ngettext('%(num)d pose', '%(num)d poses', 5), _('Pause')];
    }""")
    assert got == ["作動中", "姿勢 1 個", "姿勢 5 個", "一時停止"]


def said_payloads() -> dict:
    """Sentences as the server pushes them to every viewer, made by the real code and sent as JSON."""
    breach = with_wire({"state": "outside", "message": breach_at(DOCK, 0.5, 0.5)})
    quality, why = verdict(12345.0, None, 0.0, 0.0)
    link = with_wire({"quality": quality, "why": why})
    return json.loads(json.dumps({"breach": breach, "link": link, "plain": {"message": "a robot's own words"},
                                  "unknown": with_wire({"message": Text("not in any catalogue %(x)s", {"x": 1})})}))


@pytest.mark.parametrize("lang,breach,link", [
    ("en", "the robot left the geofence: (0.5000000, 0.5000000) is inside the geofence's keep-out area 'dock'",
     "12,345 ms round trip"),
    ("es", "el robot salió de la geovalla: (0.5000000, 0.5000000) está dentro de zona prohibida 'dock' de la geovalla",
     "12.345 ms de ida y vuelta"),
    ("ja", "ロボットがジオフェンスの外に出ました: "
     "(0.5000000, 0.5000000) はジオフェンスの 禁止エリア 'dock' の内側にあります",
     "往復 12,345 ms"),
])
def test_what_the_server_said_is_shown_in_the_pages_language(page, server, lang, breach, link):
    """A sentence made once for every viewer (api_messages.said) carries its id and values beside its English;
    each page translates it, a sentence within it too, with its numbers in the page's locale."""
    open_page(page, server, lang)
    payloads = said_payloads()
    got = page.evaluate("""(p) => {
        const { said } = window.i18n;
        return [said(p.breach, 'message'), said(p.link, 'why'), said(p.plain, 'message'), said(p.unknown, 'message'),
                said(null, 'message'), said({}, 'message')];
    }""", payloads)
    assert got == [breach, link, "a robot's own words", "not in any catalogue 1", "", ""]
    # The English beside the wire form is what an English page, curl and the logs read.
    english = payloads["breach"]["message"]
    assert (english == got[0]) == (lang == "en")


def test_a_catalogue_that_cannot_be_loaded_leaves_the_page_working_in_english(page, server):
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    open_page(page, server, "missing")
    assert page.locator("#word").inner_text() == "ENGAGED"
    assert page.evaluate("window.i18n._('Pause')") == "Pause"
    # The numbers still follow the page's language: only the words fell back.
    assert page.evaluate("window.i18n.formatNumber(0.25, 2)") == "0,25"
    assert any("catalogue.xx.json could not be loaded" in e for e in errors), errors


def test_modules_waiting_for_a_slow_catalogue_still_run_after_the_page_scripts(page, server):
    """DOMContentLoaded does not wait for a module's top-level await: afterPageScripts must still call back."""
    open_page(page, server, "slow")
    events = page.evaluate("window.events")
    assert events == ["dcl", "module ran", "after page scripts"], events
    assert page.locator("#word").inner_text() == "ACTIVADA"


def test_a_bad_language_tag_falls_back_to_english(page, server):
    open_page(page, server, "bad_lang")
    assert page.evaluate("[window.i18n.locale, window.i18n.formatNumber(1234.5, 1)]") == ["en", "1,234.5"]


def test_a_catalogue_that_never_comes_does_not_hold_the_page(page, server):
    """A stalled fetch (a radio link that went quiet) ends after i18n.js's wait: the modules run, in English."""
    errors = []
    page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
    started = time.monotonic()
    open_page(page, server, "hang")
    waited = time.monotonic() - started
    assert 7.5 < waited < 20, waited
    assert page.locator("#word").inner_text() == "ENGAGED"
    assert any("could not be loaded" in e for e in errors), errors
