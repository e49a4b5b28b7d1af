"""The shipped catalogues, read from their .po files at start: the pages' translations and the browser's JSON.

translations/<lang>/LC_MESSAGES/*.po are the only source. Each start compiles them (in memory, with
Babel's own .mo writer) so what is served is always what the .po files say: no compiled file is
committed, and none can be left stale. Every .po domain file of a language is folded into one
catalogue (the pages' messages.po, and any browser.po, api.po or events.po beside it), since the
pages, the API's messages and the browser code share one set of message ids.

The browser's catalogue is the part the browser code uses: entries located in static/js, and every
entry of events.po, the sentences the server pushes to every viewer (api_messages.said), which each
browser translates from their id and values.
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from io import BytesIO
from pathlib import Path

from babel.messages.catalog import Catalog
from babel.messages.mofile import write_mo
from babel.messages.pofile import read_po
from babel.support import Translations

log = logging.getLogger(__name__)

SOURCE = "en"  # the message ids are the English text: no catalogue is needed for it
BROWSER_SOURCES = "static/js/"  # a `#:` location under here: the browser code uses the entry
BROWSER_DOMAINS = ("events",)  # every entry of these .po files goes to the browser too
SAID = "rover-web-said"  # the flag read_language puts on such an entry (never written to a file)


@dataclass(frozen=True)
class Compiled:
    locale: str
    translations: Translations
    browser: bytes  # the browser's catalogue, as served (see browser_catalogue)


def read_language(folder: Path, locale: str) -> Catalog:
    """Every .po file of one language, folded into one catalogue (the first file, by name, wins a clash).

    The plural rule is the locale's own (CLDR's, as `pybabel init` writes it into each file)."""
    merged = Catalog(locale=locale)
    for path in sorted((folder / "LC_MESSAGES").glob("*.po")):
        with path.open("rb") as f:
            part = read_po(f, locale=locale)
        for message in part:
            if not message.id:
                continue
            held = merged.get(message.id)
            if path.stem in BROWSER_DOMAINS:
                (message if held is None else held).flags.add(SAID)
            if held is None:
                merged[message.id] = message
            else:
                if held.string != message.string and message.string:
                    log.warning("translations/%s: %r is translated differently in %s; the first is kept",
                                locale, message.id, path.name)
                held.locations = list(dict.fromkeys([*held.locations, *message.locations]))
    return merged


def translated(message) -> bool:
    """Translated and not fuzzy: what may be shown (Babel's .mo writer also leaves fuzzy entries out)."""
    if message.fuzzy:
        return False
    strings = message.string if isinstance(message.string, tuple | list) else (message.string,)
    return bool(strings) and all(strings)


def browser_catalogue(catalog: Catalog) -> dict:
    """The entries the browser code uses, in the shape static/js/core/i18n.js reads."""
    messages, plurals = {}, {}
    for message in catalog:
        if not message.id or not translated(message):
            continue
        if SAID not in message.flags and not any(path.startswith(BROWSER_SOURCES) for path, _line in message.locations):
            continue
        if isinstance(message.id, tuple | list):
            plurals[message.id[0]] = list(message.string)
        else:
            messages[message.id] = message.string
    return {"locale": str(catalog.locale), "messages": messages, "plurals": plurals}


def compile_language(folder: Path, locale: str) -> Compiled:
    catalog = read_language(folder, locale)
    buffer = BytesIO()
    write_mo(buffer, catalog, use_fuzzy=False)
    buffer.seek(0)
    browser = json.dumps(browser_catalogue(catalog), ensure_ascii=False, sort_keys=True,
                         separators=(",", ":")).encode("utf-8")
    return Compiled(locale, Translations(fp=buffer), browser)


def compile_all(root: Path, locales: tuple[str, ...]) -> dict[str, Compiled]:
    """Each shipped language but the source one. A language without a folder is served in English, said once."""
    compiled = {}
    for locale in locales:
        if locale == SOURCE:
            continue
        folder = root / locale
        if not (folder / "LC_MESSAGES").is_dir():
            log.error("translations/%s is missing: pages asked in %s are shown in English", locale, locale)
            continue
        compiled[locale] = compile_language(folder, locale)
    return compiled
