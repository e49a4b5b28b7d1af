"""Each user's display choices: the theme (dark, daylight, or the browser's) and the language.

HTTP (routes.py; docs/preferences.md):
  GET /api/me/preferences   the caller's choices, and whether they are kept for a user or a browser
  PUT /api/me/preferences   {"theme"?, "language"?}: change some; kept per user on the robot
A browser keeps the same choices itself (localStorage, and cookies so the server renders the page in
them from the first byte); signed in, the user's saved choices win, so they follow the user to any
browser. With sign-in off there is no user: the choices are the browser's alone.
Templates read `preferences` (the request's effective choices) from the context.
"""

from __future__ import annotations

from flask import Flask

from rover_web.core.state import Rover

from . import routes
from .service import LANGUAGE_NAMES, LANGUAGES, THEMES, PreferenceService, effective
from .store import PreferenceStore

__all__ = ["init_app", "PreferenceService", "effective", "LANGUAGES", "THEMES"]


def init_app(app: Flask, rover: Rover) -> None:
    """After auth (the choices are the signed-in user's); `rover` holds the app's database."""
    rover.add_feature(PreferenceService(PreferenceStore(rover.db)))
    app.register_blueprint(routes.bp)
    app.context_processor(lambda: {"preferences": effective(), "language_names": LANGUAGE_NAMES})
