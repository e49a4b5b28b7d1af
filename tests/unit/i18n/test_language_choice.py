"""Which language a page is drawn in: the browser's Accept-Language, the cookie over it, and only
the shipped languages; `<html lang>` and the browser catalogue's URL say it on every page."""

import re

import pytest
from babel.messages.pofile import read_po

from rover_web.config import ROOT


def html_tag(body: str) -> str:
    return re.search(r"<html[^>]*>", body).group(0)


def page_lang(client, path="/", **headers) -> tuple[str, str | None]:
    answer = client.get(path, headers=headers)
    tag = html_tag(answer.get_data(as_text=True))
    catalogue = re.search(r'data-catalogue="([^"]+)"', tag)
    return re.search(r'lang="([^"]*)"', tag).group(1), catalogue.group(1) if catalogue else None


def po_string(lang: str, msgid: str) -> str:
    with (ROOT / "translations" / lang / "LC_MESSAGES" / "messages.po").open("rb") as f:
        return read_po(f)[msgid].string


@pytest.mark.parametrize(("accept", "lang"), [
    ("es-MX,es;q=0.9,en;q=0.5", "es"),     # a region falls back to its language
    ("ja-JP", "ja"),
    ("fr, ja;q=0.3", "ja"),                # the best of what is shipped, not the first asked
    ("fr, de", "en"),                      # none shipped: English
    ("", "en"),
    ("en-US,ja;q=0.9", "en"),
])
def test_accept_language_picks_the_best_shipped_language(client, accept, lang):
    assert page_lang(client, **({"Accept-Language": accept} if accept else {}))[0] == lang


def test_the_cookie_wins_over_accept_language_and_a_bad_one_is_ignored(client):
    client.set_cookie("rover_web_lang", "ja")
    assert page_lang(client, **{"Accept-Language": "es"})[0] == "ja"
    client.set_cookie("rover_web_lang", "auto")  # the browser's Accept-Language
    assert page_lang(client, **{"Accept-Language": "es"})[0] == "es"
    for bad in ("xx", "ja; lang=es", "../en", "ES", "e" * 300):
        client.set_cookie("rover_web_lang", bad)
        assert page_lang(client, **{"Accept-Language": "es"})[0] == "es", bad


def test_pages_outside_the_base_template_say_their_language_too(client):
    client.set_cookie("rover_web_lang", "es")
    for path in ("/", "/api/docs", "/no/such/page"):
        assert page_lang(client, path)[0] == "es", path


def test_the_page_is_drawn_from_the_catalogue(client):
    client.set_cookie("rover_web_lang", "ja")
    body = client.get("/").get_data(as_text=True)
    assert po_string("ja", "Dashboard") in body and po_string("ja", "Errors") in body
    assert ">Dashboard<" not in body
    client.set_cookie("rover_web_lang", "en")
    assert ">Dashboard<" in client.get("/").get_data(as_text=True)


def test_english_has_no_browser_catalogue_and_the_others_a_hashed_immutable_one(client):
    client.set_cookie("rover_web_lang", "en")
    assert page_lang(client)[1] is None
    for lang in ("es", "ja"):
        client.set_cookie("rover_web_lang", lang)
        url = page_lang(client)[1]
        assert re.fullmatch(rf"/static/i18n/{lang}\.[0-9a-f]{{12}}\.json", url), url
        answer = client.get(url)
        assert answer.status_code == 200 and "immutable" in answer.headers["Cache-Control"]
        assert answer.get_json()["locale"] == lang
