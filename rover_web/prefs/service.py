"""What a request's page is shown in: the user's saved choices over the browser's cookies.

The cookies are the browser's own copy (the page writes them with localStorage): they let the
server render the first byte in the right theme and language before any script runs. They are
read, never trusted beyond the allowed values.
"""

from __future__ import annotations

from flask import g, request

from rover_web.auth.identity import signed_in_name
from rover_web.core.state import NotSetUp, current_feature
from rover_web.web.validate import InvalidInput

from .store import PreferenceStore

THEMES = ("auto", "dark", "daylight")
# The shipped catalogues (translations/); "auto" is the browser's Accept-Language.
LANGUAGES = ("auto", "en", "es", "ja")
# Each language named in itself (its autonym), as a language picker shows it: never translated.
LANGUAGE_NAMES = {"en": "English", "es": "Español", "ja": "日本語"}
ALLOWED = {"theme": THEMES, "language": LANGUAGES}
DEFAULTS = {"theme": "auto", "language": "auto"}
COOKIES = {"theme": "rover_web_theme", "language": "rover_web_lang"}


class PreferenceService:
    def __init__(self, store: PreferenceStore):
        self.store = store

    def for_user(self, user: str | None) -> dict:
        return self.store.get(user) if user else {}


def check(body: dict) -> dict:
    """The body's changes, or InvalidInput naming the field (nothing is saved then)."""
    changes = {}
    for key, value in body.items():
        allowed = ALLOWED.get(key)
        if allowed is None:
            raise InvalidInput("unknown field %(key)s; allowed: %(allowed)s", "unknown_field",
                               key=repr(key), allowed=', '.join(ALLOWED))
        if not isinstance(value, str):
            raise InvalidInput("'%(key)s' must be a string, one of: %(allowed)s", "bad_type",
                               key=key, allowed=', '.join(allowed))
        if value not in allowed:
            raise InvalidInput("'%(key)s' must be one of: %(allowed)s (not %(value)s)", "bad_value",
                               key=key, allowed=', '.join(allowed), value=repr(value[:40]))
        changes[key] = value
    return changes


def from_cookies() -> dict:
    chosen = {}
    for key, cookie in COOKIES.items():
        value = request.cookies.get(cookie)
        if value in ALLOWED[key]:
            chosen[key] = value
    return chosen


def effective() -> dict:
    """The request's choices: defaults, under the browser's cookies, under the signed-in user's own.

    Read once a request (kept on flask.g): the language selector, the page's context and an API
    error's message all ask, and a signed-in user's choices are a database read."""
    if "rover_web_preferences" not in g:
        try:
            service = current_feature(PreferenceService)
        except NotSetUp:  # a page of an app without users (none so far); the browser's choices alone
            service = None
        saved = service.for_user(signed_in_name()) if service is not None else {}
        g.rover_web_preferences = {**DEFAULTS, **from_cookies(), **saved}
    return dict(g.rover_web_preferences)
