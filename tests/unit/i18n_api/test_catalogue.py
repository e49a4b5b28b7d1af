"""The API's messages are all extractable, and every one is translated in each shipped language.

The extraction is the real `pybabel extract` over rover_web/ with the keywords of message_sites.py
(the ones translations/api_babel.cfg and docs/i18n_api.md give), so a message written so that Babel
cannot see it, or seen but missing from a catalogue, fails here before it ships.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from babel.messages.pofile import read_po

from tests.unit.i18n_api.message_sites import KEYWORDS, ROOT, problems

LANGUAGES = ("es", "ja")
PLACEHOLDER = re.compile(r"%\((\w+)\)[sd]")
FIELD = re.compile(r"'\w+'|\w+\[\]")  # 'value', features[] once the placeholders are gone


@pytest.fixture(scope="module")
def extracted(tmp_path_factory) -> dict[str, object]:
    pot = tmp_path_factory.mktemp("pot") / "api.pot"
    pybabel = Path(sys.executable).with_name("pybabel")
    command = [str(pybabel), "extract", "-F", str(ROOT / "translations" / "api_babel.cfg"), "--no-default-keywords",
               *[arg for keyword in KEYWORDS for arg in ("-k", keyword)], "-o", str(pot), str(ROOT)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # Babel skips an f-string at a keyword's call without failing; such a message is never translated.
    skipped = [line for line in done.stderr.splitlines() if "warning" in line]
    assert not skipped, "\n".join(skipped)
    with pot.open("rb") as f:
        return {m.id: m for m in read_po(f) if m.id}


def _catalogue(lang: str):
    with (ROOT / "translations" / lang / "LC_MESSAGES" / "api.po").open("rb") as f:
        return read_po(f, locale=lang)


def test_every_message_site_is_a_literal_babel_extracts():
    assert problems() == []


def test_the_extraction_finds_the_api_messages(extracted):
    # A keyword list that silently found nothing would make every other check here pass.
    assert len(extracted) > 400
    assert "no layout %(layout_id)s on this robot; GET /api/layouts lists them" in extracted
    assert "'%(key)s' is required" in extracted  # InvalidInput in web/validate.py
    assert "the e-stop is engaged: nobody takes control until it is released" in extracted  # explain()


def test_the_committed_template_is_the_extraction(extracted):
    with (ROOT / "translations" / "api.pot").open("rb") as f:
        committed = {m.id for m in read_po(f) if m.id}
    assert committed == set(extracted), "run the extraction again (docs/i18n_api.md)"


@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_message_is_translated_and_none_is_fuzzy(extracted, lang):
    catalogue = _catalogue(lang)
    missing = [msgid for msgid in extracted if catalogue.get(msgid) is None or not catalogue.get(msgid).string]
    fuzzy = [m.id for m in catalogue if m.id and m.fuzzy]
    assert missing == []
    assert fuzzy == []


@pytest.mark.parametrize("lang", LANGUAGES)
def test_a_translation_has_the_same_placeholders_as_its_msgid(extracted, lang):
    wrong = []
    for m in _catalogue(lang):
        if m.id and m.string and set(PLACEHOLDER.findall(m.string)) != set(PLACEHOLDER.findall(m.id)):
            wrong.append((m.id, m.string))
    assert wrong == []


@pytest.mark.parametrize("lang", LANGUAGES)
def test_no_translation_is_left_in_english(extracted, lang):
    # A msgstr copied from its msgid would pass the checks above and still show English; only
    # messages that are nothing but values and field names (e.g. "features[%(i)s]: %(why)s") may
    # stay as they are.
    def words(msgid: str) -> str:
        return FIELD.sub("", PLACEHOLDER.sub("", msgid)).strip(" :;.()[]")

    same = [m.id for m in _catalogue(lang) if m.id and m.string == m.id and words(m.id)]
    assert same == []
