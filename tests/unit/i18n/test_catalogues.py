"""The shipped catalogues are complete, and what the server serves is what the .po files say.

The message ids are extracted here with Babel's own extraction and the project's babel.cfg, as
`pybabel extract` does: a string wrapped in a template, in Python or in static/js and not
translated (or left fuzzy) in a shipped language fails this test before it can ship.
"""

from __future__ import annotations

import os
import re
import shutil

import pytest
from babel.messages.extract import extract_from_dir
from babel.messages.frontend import parse_mapping_cfg

from rover_web import i18n
from rover_web.config import ROOT
from rover_web.i18n.catalogues import browser_catalogue, compile_language, read_language, translated

SHIPPED = ("es", "ja")
PLACEHOLDER = re.compile(r"%\((\w+)\)[sd]")


@pytest.fixture(scope="module")
def extracted() -> dict[str, list[str]]:
    """Every message id in the sources (singular id -> where), by the real extraction."""
    with (ROOT / "babel.cfg").open() as f:
        method_map, options_map = parse_mapping_cfg(f)
    found: dict[str, list[str]] = {}
    # Only the folders babel.cfg names are walked (build/ holds thousands of hashed static files).
    sources = {"rover_web", "templates", "static"}
    walked = extract_from_dir(str(ROOT), method_map, options_map,
                              directory_filter=lambda path: os.path.relpath(path, ROOT).split(os.sep)[0] in sources)
    for filename, lineno, message, _comments, _context in walked:
        msgid = message[0] if isinstance(message, tuple) else message
        found.setdefault(msgid, []).append(f"{filename}:{lineno}")
    return found


def test_the_sources_have_messages(extracted):
    assert "Dashboard" in extracted and "Sign out" in extracted  # the extraction reads Python and templates
    assert any(where.startswith("templates/") for places in extracted.values() for where in places)


@pytest.mark.parametrize("lang", SHIPPED)
def test_every_extracted_message_is_translated(extracted, lang):
    catalog = read_language(ROOT / "translations" / lang, lang)
    problems = []
    for msgid, where in extracted.items():
        message = catalog.get(msgid) or next((m for m in catalog if isinstance(m.id, tuple) and m.id[0] == msgid),
                                             None)
        if message is None:
            problems.append(f"missing: {msgid!r} ({where[0]})")
        elif not translated(message):
            problems.append(f"{'fuzzy' if message.fuzzy else 'untranslated'}: {msgid!r} ({where[0]})")
    assert problems == [], f"translations/{lang}: run the commands of docs/i18n.md, then translate"


@pytest.mark.parametrize("lang", SHIPPED)
def test_translations_keep_the_placeholders(lang):
    """A translation that drops or renames %(name)s would fail at render; Babel's own checks too."""
    catalog = read_language(ROOT / "translations" / lang, lang)
    problems = [f"{message.id!r}: {errors}" for message, errors in catalog.check()]
    for message in catalog:
        if not message.id or not message.string:
            continue
        ids = message.id if isinstance(message.id, tuple) else (message.id,)
        strings = message.string if isinstance(message.string, tuple) else (message.string,)
        wanted = set(PLACEHOLDER.findall(" ".join(ids))) - {"num"}  # ngettext may leave the count implied
        for string in strings:
            if set(PLACEHOLDER.findall(string)) - {"num"} != wanted:
                problems.append(f"{message.id!r} -> {string!r}")
    assert problems == []


@pytest.mark.parametrize("lang", SHIPPED)
def test_a_message_id_has_one_translation_across_the_files(lang):
    """The pages (messages.po), the browser code (browser.po) and the API (api.po) share message ids:
    one word must not read two ways on one screen (the start would keep one and warn about the other)."""
    from babel.messages.pofile import read_po

    seen, clashes = {}, []
    for path in sorted((ROOT / "translations" / lang / "LC_MESSAGES").glob("*.po")):
        with path.open("rb") as f:
            for message in read_po(f, locale=lang):
                if not message.id or not message.string:
                    continue
                first = seen.setdefault(message.id, (path.name, message.string))
                if first[1] != message.string:
                    clashes.append(f"{message.id!r}: {first[0]} {first[1]!r}, {path.name} {message.string!r}")
    assert clashes == []


def write_po(path, lang, entries):
    header = (f'msgid ""\nmsgstr ""\n"Language: {lang}\\n"\n"Content-Type: text/plain; charset=utf-8\\n"\n'
              '"Plural-Forms: nplurals=3; plural=(n == 1 ? 0 : n != 0 && n % 1000000 == 0 ? 1 : 2);\\n"\n\n')
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(header + "\n".join(entries), encoding="utf-8")


def test_the_browser_catalogue_holds_the_browser_codes_translated_entries(tmp_path):
    """Built from every .po of the language (messages.po and a browser.po beside it, as before and after
    the merge): entries located in static/js and every entry of events.po, never a fuzzy or untranslated
    one, nor an API error's (the server translates those itself)."""
    folder = tmp_path / "es"
    write_po(folder / "LC_MESSAGES" / "messages.po", "es", [
        '#: templates/base.html:3\nmsgid "Sign out"\nmsgstr "Cerrar sesión"\n',
        '#: templates/base.html:4 static/js/live/live.js:9\nmsgid "Robot"\nmsgstr "Robot (es)"\n',
    ])
    write_po(folder / "LC_MESSAGES" / "browser.po", "es", [
        '#: static/js/teleop/stick.js:12\nmsgid "Stop"\nmsgstr "Detener"\n',
        '#: static/js/teleop/stick.js:13\nmsgid "%(num)d robot"\nmsgid_plural "%(num)d robots"\n'
        'msgstr[0] "%(num)d robot"\nmsgstr[1] "%(num)d de robots"\nmsgstr[2] "%(num)d robots"\n',
        '#: static/js/teleop/stick.js:14\n#, fuzzy\nmsgid "Go"\nmsgstr "Ir"\n',
        '#: static/js/teleop/stick.js:15\nmsgid "Later"\nmsgstr ""\n',
    ])
    # What the server says to every viewer (api_messages.said): located in Python, sent all the same.
    write_po(folder / "LC_MESSAGES" / "events.po", "es", [
        '#: rover_web/teleop/link.py:9\nmsgid "%(ms)d ms jitter"\nmsgstr "%(ms)d ms de fluctuación"\n',
        '#: rover_web/teleop/link.py:10\n#, fuzzy\nmsgid "a stall"\nmsgstr "un bloqueo"\n',
    ])
    write_po(folder / "LC_MESSAGES" / "api.po", "es", [
        '#: rover_web/web/http.py:9\nmsgid "no such route"\nmsgstr "no existe la ruta"\n',
    ])
    compiled = compile_language(folder, "es")
    import json

    assert json.loads(compiled.browser) == {
        "locale": "es",
        "messages": {"Robot": "Robot (es)", "Stop": "Detener", "%(ms)d ms jitter": "%(ms)d ms de fluctuación"},
        "plurals": {"%(num)d robot": ["%(num)d robot", "%(num)d de robots", "%(num)d robots"]},
    }
    # The pages' translations come from the same files; fuzzy and untranslated stay English.
    t = compiled.translations
    assert (t.gettext("Sign out"), t.gettext("Stop"), t.gettext("Go"), t.gettext("Later")) == \
        ("Cerrar sesión", "Detener", "Go", "Later")
    assert t.ngettext("%(num)d robot", "%(num)d robots", 2) == "%(num)d robots"
    assert t.gettext("no such route") == "no existe la ruta"
    assert t.gettext("%(ms)d ms jitter") == "%(ms)d ms de fluctuación"


@pytest.fixture
def own_translations(tmp_path, monkeypatch):
    """A copy of translations/ the app reads instead, for a test to change."""
    copy = tmp_path / "translations"
    shutil.copytree(ROOT / "translations", copy)
    monkeypatch.setattr(i18n, "TRANSLATIONS", copy)
    return copy


def test_what_is_served_is_what_the_po_files_say_at_start(app_factory, own_translations):
    """Edit a .po, start: the page and the browser catalogue carry the edit (no compiled file to go stale)."""
    po = own_translations / "es" / "LC_MESSAGES" / "messages.po"
    text = po.read_text(encoding="utf-8")
    assert 'msgid "Dashboard"\nmsgstr "Panel"\n' in text
    po.write_text(text.replace('msgid "Dashboard"\nmsgstr "Panel"\n', 'msgid "Dashboard"\nmsgstr "Tablero"\n')
                  + '\n#: static/js/test/probe.js:1\nmsgid "Probe for the test"\nmsgstr "Sonda de la prueba"\n',
                  encoding="utf-8")
    client = app_factory().test_client()
    client.set_cookie("rover_web_lang", "es")
    page = client.get("/").get_data(as_text=True)
    assert 'lang="es"' in page and ">Tablero<" in page
    url = re.search(r'data-catalogue="([^"]+)"', page).group(1)
    served = client.get(url).get_json()
    assert served == browser_catalogue(read_language(own_translations / "es", "es"))
    assert served["messages"]["Probe for the test"] == "Sonda de la prueba"


def test_the_served_catalogue_matches_the_shipped_po(client):
    for lang in SHIPPED:
        client.set_cookie("rover_web_lang", lang)
        url = re.search(r'data-catalogue="([^"]+)"', client.get("/").get_data(as_text=True)).group(1)
        assert client.get(url).get_json() == browser_catalogue(read_language(ROOT / "translations" / lang, lang))
