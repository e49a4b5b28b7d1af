"""The browser code's catalogue (issue 43): every _() and ngettext() call in static/js is found by Babel's
real extraction, and every message it finds is translated, not fuzzy, in Spanish and Japanese, with the
same placeholders. A new string left out of browser.po fails here before it ships in English."""

from __future__ import annotations

import ast
import collections
import functools
import re

import pytest
from babel.messages.extract import extract_from_dir
from babel.messages.pofile import read_po

from rover_web.config import ROOT

STATIC_JS = ROOT / "static" / "js"
TRANSLATIONS = ROOT / "translations"
CONFIG = TRANSLATIONS / "babel_browser.cfg"
LANGUAGES = ("es", "ja")
# What `pybabel extract -F translations/babel_browser.cfg -k _ -k ngettext:1,2` uses.
KEYWORDS = {"_": None, "ngettext": (1, 2)}
OPTIONS = {"**.js": {"parse_template_string": "true"}}
# A call of _ or ngettext (not a method, not part of a name), and its first argument when that is a
# plain string literal.
CALL = re.compile(r"""(?<![\w.$])(_|ngettext)\(\s*('(?:[^'\\\n]|\\.)*'|"(?:[^"\\\n]|\\.)*")?""")
PLACEHOLDER = re.compile(r"%\((\w+)\)[sd]")


@functools.cache
def extracted() -> dict:
    """Babel's own extraction of static/js: {(path under static/js, message id): count}."""
    found = collections.Counter()
    for path, _line, message, _comments, _context in extract_from_dir(
            str(STATIC_JS), [("**.js", "javascript")], options_map=OPTIONS, keywords=KEYWORDS):
        found[(path, message[0] if isinstance(message, tuple) else message)] += 1
    return found


def calls_in_source() -> tuple[dict, list]:
    """Each call in the code, read with a regular expression: {(path, message id): count}, and calls whose
    message id is not a plain string literal (a template literal or a variable: nothing to extract)."""
    calls, not_literal = collections.Counter(), []
    for path in sorted(STATIC_JS.rglob("*.js")):
        name = path.relative_to(STATIC_JS).as_posix()
        if name == "core/i18n.js":
            continue  # where _ and ngettext are defined
        text = path.read_text(encoding="utf-8")
        for match in CALL.finditer(text):
            line_start = text.rfind("\n", 0, match.start()) + 1
            if text[line_start:match.start()].lstrip().startswith("//"):
                continue
            if match.group(2) is None:
                not_literal.append(f"{name}:{text.count(chr(10), 0, match.start()) + 1}")
                continue
            calls[(name, ast.literal_eval(match.group(2)))] += 1
    return calls, not_literal


def catalogue(language: str):
    with (TRANSLATIONS / language / "LC_MESSAGES" / "browser.po").open("rb") as f:
        return read_po(f, locale=language)


def test_babel_extracts_every_call_in_the_browser_code():
    calls, not_literal = calls_in_source()
    assert not not_literal, f"message ids must be plain string literals: {not_literal}"
    found = extracted()
    assert len(calls) > 300  # the check is looking at the code, not at nothing
    # Babel's JavaScript lexer misses, e.g., a call nested in another's arguments: each would ship in English.
    assert calls - found == collections.Counter(), "calls Babel's extraction does not see"
    assert found - calls == collections.Counter()


def test_no_message_id_is_a_template_literal():
    assert not [m for _path, m in extracted() if "${" in m]


def test_the_template_is_babels_extraction_as_committed():
    with (TRANSLATIONS / "browser.pot").open("rb") as f:
        template = {m.id if isinstance(m.id, str) else tuple(m.id) for m in read_po(f) if m.id}
    ids = {message if isinstance(message, str) else tuple(message)
           for _p, _l, message, _c, _x in extract_from_dir(str(STATIC_JS), [("**.js", "javascript")],
                                                          options_map=OPTIONS, keywords=KEYWORDS)}
    assert template == ids, "run the pybabel extract of docs/i18n_browser.md, then pybabel update"


@pytest.mark.parametrize("language", LANGUAGES)
def test_every_browser_message_is_translated_not_fuzzy_with_the_same_placeholders(language):
    po = catalogue(language)
    held = {m.id if isinstance(m.id, str) else tuple(m.id): m for m in po if m.id}
    problems = []
    for (path, message_id), _count in extracted().items():
        message = held.get(message_id) or next((m for k, m in held.items() if isinstance(k, tuple)
                                                and k[0] == message_id), None)
        where = f"static/js/{path}: {message_id!r}"
        if message is None:
            problems.append(f"missing {where}")
            continue
        if message.fuzzy:
            problems.append(f"fuzzy {where}")
        strings = message.string if isinstance(message.string, tuple) else (message.string,)
        if isinstance(message.id, tuple) and len(strings) != po.num_plurals:
            problems.append(f"{len(strings)} plural forms, not {po.num_plurals}: {where}")
        if not all(strings):
            problems.append(f"untranslated {where}")
        wanted = set(PLACEHOLDER.findall(message.id if isinstance(message.id, str) else " ".join(message.id)))
        for text in strings:
            if text and set(PLACEHOLDER.findall(text)) != wanted:
                problems.append(f"placeholders {sorted(PLACEHOLDER.findall(text))} != {sorted(wanted)}: {where}")
        if not any(location.startswith("static/js/") for location, _line in message.locations):
            problems.append(f"no static/js location (the server would not send it to the browser): {where}")
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("language", LANGUAGES)
def test_the_catalogue_holds_only_what_the_code_says(language):
    ids = {message for _path, message in extracted()}
    stale = [m.id for m in catalogue(language)
             if m.id and (m.id if isinstance(m.id, str) else m.id[0]) not in ids and not m.obsolete]
    assert not stale, f"in browser.po but no longer in static/js (pybabel update marks them obsolete): {stale}"


def test_a_missing_translation_is_caught(tmp_path):
    """The check above fails on a new call with no entry: made with a real file and Babel's real extraction."""
    (tmp_path / "x.js").write_text("el.textContent = _('A brand new string');\n", encoding="utf-8")
    found = [m for _p, _l, m, _c, _x in extract_from_dir(str(tmp_path), [("**.js", "javascript")],
                                                          options_map=OPTIONS, keywords=KEYWORDS)]
    assert found == ["A brand new string"]
    assert all(m.id != "A brand new string" for m in catalogue("es"))


def test_the_extraction_config_is_the_one_documented():
    text = CONFIG.read_text(encoding="utf-8")
    assert "[javascript: **.js]" in text and "parse_template_string = true" in text
    doc = (ROOT / "docs" / "i18n_browser.md").read_text(encoding="utf-8")
    assert "-k _ -k ngettext:1,2" in doc and "translations/babel_browser.cfg" in doc

