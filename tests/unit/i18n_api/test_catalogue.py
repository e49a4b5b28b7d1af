"""The API's messages and the sentences pushed to every viewer are all extractable, and every one is
translated in each shipped language.

The extraction is the real `pybabel extract` over rover_web/ with the keywords of message_sites.py
(the ones translations/api_babel.cfg, translations/events_babel.cfg and docs/i18n_api.md give), so a
message written so that Babel cannot see it, or seen but missing from a catalogue, fails here before
it ships. Each domain (api, events) is checked alike.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from babel.messages.pofile import read_po

from tests.unit.i18n_api.message_sites import EVENT_KEYWORDS, KEYWORDS, ROOT, problems

LANGUAGES = ("es", "ja")
PLACEHOLDER = re.compile(r"%\((\w+)\)[sd]")
FIELD = re.compile(r"'\w+'|\w+\[\]")  # 'value', features[] once the placeholders are gone


DOMAINS = {"api": ("api_babel.cfg", KEYWORDS), "events": ("events_babel.cfg", EVENT_KEYWORDS)}


def extract(domain: str, folder: Path) -> dict[str, object]:
    config, keywords = DOMAINS[domain]
    pot = folder / f"{domain}.pot"
    pybabel = Path(sys.executable).with_name("pybabel")
    command = [str(pybabel), "extract", "-F", str(ROOT / "translations" / config), "--no-default-keywords",
               *[arg for keyword in keywords for arg in ("-k", keyword)], "-o", str(pot), str(ROOT)]
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    # Babel skips an f-string at a keyword's call without failing; such a message is never translated.
    skipped = [line for line in done.stderr.splitlines() if "warning" in line]
    assert not skipped, "\n".join(skipped)
    with pot.open("rb") as f:
        return {m.id: m for m in read_po(f) if m.id}


@pytest.fixture(scope="module")
def extractions(tmp_path_factory) -> dict[str, dict]:
    return {domain: extract(domain, tmp_path_factory.mktemp(domain)) for domain in DOMAINS}


@pytest.fixture(scope="module")
def extracted(extractions) -> dict[str, object]:
    return extractions["api"]


def _catalogue(lang: str, domain: str = "api"):
    with (ROOT / "translations" / lang / "LC_MESSAGES" / f"{domain}.po").open("rb") as f:
        return read_po(f, locale=lang)


def test_every_message_site_is_a_literal_babel_extracts():
    assert problems() == []


def test_the_extraction_finds_the_api_messages(extracted):
    # A keyword list that silently found nothing would make every other check here pass.
    assert len(extracted) > 400
    assert "no layout %(layout_id)s on this robot; GET /api/layouts lists them" in extracted
    assert "'%(key)s' is required" in extracted  # InvalidInput in web/validate.py
    assert "the e-stop is engaged: nobody takes control until it is released" in extracted  # explain()


def test_the_extraction_finds_the_sentences_said_to_every_viewer(extractions):
    said = extractions["events"]
    assert len(said) > 40
    assert "the robot left the geofence: %(why)s" in said  # geofence/service.py
    assert "%(ms)d ms round trip" in said  # teleop/link.py
    # One file each: a sentence said to every viewer is in events.po alone (a msgid of nothing but a
    # placeholder, "%(why)s", may be in both: it has nothing to translate).
    both = set(said) & set(extractions["api"])
    assert {msgid for msgid in both if PLACEHOLDER.sub("", msgid).strip()} == set()


@pytest.mark.parametrize("domain", DOMAINS)
def test_the_committed_template_is_the_extraction(extractions, domain):
    with (ROOT / "translations" / f"{domain}.pot").open("rb") as f:
        committed = {m.id for m in read_po(f) if m.id}
    assert committed == set(extractions[domain]), "run the extraction again (docs/i18n_api.md)"


@pytest.mark.parametrize("domain", DOMAINS)
@pytest.mark.parametrize("lang", LANGUAGES)
def test_every_message_is_translated_and_none_is_fuzzy(extractions, lang, domain):
    catalogue = _catalogue(lang, domain)
    missing = [msgid for msgid in extractions[domain]
               if catalogue.get(msgid) is None or not catalogue.get(msgid).string]
    fuzzy = [m.id for m in catalogue if m.id and m.fuzzy]
    assert missing == []
    assert fuzzy == []


@pytest.mark.parametrize("domain", DOMAINS)
@pytest.mark.parametrize("lang", LANGUAGES)
def test_a_translation_has_the_same_placeholders_as_its_msgid(lang, domain):
    wrong = []
    for m in _catalogue(lang, domain):
        if m.id and m.string and set(PLACEHOLDER.findall(m.string)) != set(PLACEHOLDER.findall(m.id)):
            wrong.append((m.id, m.string))
    assert wrong == []


@pytest.mark.parametrize("domain", DOMAINS)
@pytest.mark.parametrize("lang", LANGUAGES)
def test_no_translation_is_left_in_english(lang, domain):
    # A msgstr copied from its msgid would pass the checks above and still show English; only
    # messages that are nothing but values and field names (e.g. "features[%(i)s]: %(why)s") may
    # stay as they are.
    def words(msgid: str) -> str:
        return FIELD.sub("", PLACEHOLDER.sub("", msgid)).strip(" :;.()[]")

    same = [m.id for m in _catalogue(lang, domain) if m.id and m.string == m.id and words(m.id)]
    assert same == []
