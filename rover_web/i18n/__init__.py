"""Languages (issue 43): every page in English, Spanish or Japanese, from gettext catalogues.

  translations/<lang>/LC_MESSAGES/*.po   the catalogues (Babel's standard tools make them; docs/i18n.md)
  babel.cfg                              what `pybabel extract` reads: templates, Python, static/js
Flask-Babel gives the pages `_()`, `ngettext` and `{% trans %}` and formats numbers and dates for
the page's locale. The language of a request (locale.py): the user's or the browser's choice
(rover_web.prefs), else the browser's Accept-Language, else English.

The browser code gets the same catalogue: for each language, the entries used in static/js as a
JSON file, hashed and served immutable by the static pipeline (web/assets.py); its URL is on
`<html data-catalogue>` (none in English, the message ids themselves). Nothing is compiled ahead:
each start reads the .po files (catalogues.py), so what is served is always what they say.
"""

from __future__ import annotations

from babel.support import NullTranslations
from flask import Flask, url_for
from flask_babel import Babel, Domain, get_locale

from rover_web.config import ROOT
from rover_web.web.api_messages import Text, from_wire

from .catalogues import SOURCE, Compiled, compile_all
from .locale import LOCALES, select_locale

__all__ = ["init_app", "N_", "LOCALES", "TRANSLATIONS", "GENERATED_STATIC"]

TRANSLATIONS = ROOT / "translations"
# Files the static pipeline hashes and serves beside static/'s own (web/assets.py reads this).
GENERATED_STATIC = "rover_web.generated_static"


def N_(message: str) -> str:  # noqa: N802 - gettext's name for "extract this, translate it where it is shown"
    """Marks a string defined at import time (a nav label, a card's title) for extraction; pages translate
    it when they show it, in the request's language."""
    return message


def browser_catalogue_name(locale: str) -> str:
    return f"i18n/{locale}.json"


class _CompiledDomain(Domain):
    """Flask-Babel's domain, answering from the catalogues compiled at start instead of .mo files on disk."""

    def __init__(self, compiled: dict[str, Compiled]):
        super().__init__()
        self.compiled = compiled

    def get_translations(self):
        locale = get_locale()
        found = self.compiled.get(locale.language) if locale is not None else None
        return found.translations if found is not None else NullTranslations()


class _Babel(Babel):
    def __init__(self, app: Flask, compiled: dict[str, Compiled]):
        self._domain = _CompiledDomain(compiled)
        super().__init__(app, locale_selector=select_locale, default_locale=SOURCE)

    @property
    def domain_instance(self):
        return self._domain


def init_app(app: Flask) -> None:
    """Before web/assets.py (which serves the browser's catalogues with the static files); robot and hub alike.

    The time zone is left as the browser's: the server formats no clock times into pages without
    saying the zone, and the browser code shows times in its own (Intl)."""
    compiled = compile_all(TRANSLATIONS, LOCALES)
    _Babel(app, compiled)
    app.extensions.setdefault(GENERATED_STATIC, {}).update(
        {browser_catalogue_name(locale): c.browser for locale, c in compiled.items()})

    # A sentence the server made (api_messages.said or explain) in the page's language: `{{ x|translated }}`.
    app.jinja_env.filters["translated"] = lambda value: value.translated() if isinstance(value, Text) else value
    # One received from elsewhere in its wire form (a robot's alerts on the hub): `{{ english|from_wire(wire) }}`.
    app.jinja_env.filters["from_wire"] = lambda english, wire: from_wire(wire, english)

    @app.context_processor
    def _page_language():
        locale = get_locale()
        lang = locale.language if locale is not None else SOURCE
        return {"page_lang": lang, "page_catalogue": _catalogue_url(app, lang, compiled)}


def _catalogue_url(app: Flask, lang: str, compiled: dict[str, Compiled]) -> str | None:
    """The browser catalogue's hashed URL; None in English, or when static files are not hashed (then the
    browser code shows English rather than fetch a file no one serves)."""
    manifest = app.extensions.get("rover_web.assets")
    name = browser_catalogue_name(lang)
    if lang not in compiled or manifest is None or name not in manifest.hashed:
        return None
    return url_for("static", filename=name)
