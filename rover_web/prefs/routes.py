"""GET and PUT /api/me/preferences: any signed-in user reads and sets their own (auth/policy.py)."""

from __future__ import annotations

from flask import Blueprint, g, jsonify

from rover_web.auth.identity import signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.validate import InvalidInput

from .service import DEFAULTS, PreferenceService, check, effective

bp = Blueprint("prefs", __name__)


@bp.get("/api/me/preferences")
def get_preferences():
    user = signed_in_name()
    return jsonify(effective=effective(), saved=current_feature(PreferenceService).for_user(user),
                   defaults=DEFAULTS, user=user, kept="user" if user else "browser")


@bp.put("/api/me/preferences")
def set_preferences():
    changes = check(json_body())
    user = signed_in_name()
    if user is None:
        raise ApiError(409, "no_user", "sign-in is off or you are not signed in: these choices are kept by the "
                                       "browser (the page stores them itself), not on the robot")
    saved = current_feature(PreferenceService).store.update(user, changes)
    g.pop("rover_web_preferences", None)  # what this request renders from now on is the new choice
    return jsonify(saved=saved, user=user)


@bp.errorhandler(InvalidInput)
def _invalid(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))
