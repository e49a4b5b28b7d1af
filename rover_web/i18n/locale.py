"""The language a request's page is shown in."""

from __future__ import annotations

from flask import has_request_context, request

# The shipped languages, the source first: the fallback when the browser asks for none of them.
LOCALES = ("en", "es", "ja")


def select_locale() -> str:
    """The user's saved choice, over the browser's (cookie), unless "auto"; then Accept-Language's best
    match ("es-MX" is Spanish); else English. A bad cookie value is ignored (prefs.from_cookies)."""
    if not has_request_context():
        return LOCALES[0]
    from rover_web import prefs  # here: prefs (through auth) imports core.state, which marks its labels with N_

    chosen = prefs.effective()["language"]
    if chosen in LOCALES:
        return chosen
    # By the primary subtag, in the browser's order of preference: "en-US, ja;q=0.9" is English
    # (Werkzeug's best_match would take the exact "ja" over the regional "en-US").
    for value, _quality in request.accept_languages:  # highest quality first
        language = value.replace("_", "-").split("-", 1)[0].lower()
        if language in LOCALES:
            return language
    return LOCALES[0]
