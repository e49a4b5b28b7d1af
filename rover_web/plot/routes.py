"""GET /plot (the page), GET /api/plot (one series' recent points) and GET /api/plot/fields."""

from __future__ import annotations

import math
import time

from flask import Blueprint, jsonify, render_template, request

from rover_web.core.state import current_feature
from rover_web.topics.routes import STATUS as ECHO_STATUS
from rover_web.topics.service import EchoRefused, TopicBrowser
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError
from rover_web.web.streams import client_key, refuse_cross_site
from rover_web.web.validate import InvalidInput

from . import msgs
from .field import FieldError
from .service import NotPlottable, Plots, TooManySeries, check_plottable, oversize, series_id

bp = Blueprint("plot", __name__)

MAX_SECONDS = 24 * 3600.0
DEFAULT_SECONDS = 60.0


def _refused(exc: EchoRefused) -> ApiError:
    """The topic browser's refusal, with the status the topic browser answers it with (its subclasses too)."""
    status = next((ECHO_STATUS[cls] for cls in type(exc).__mro__ if cls in ECHO_STATUS), 503)
    return ApiError(status, exc.code, text_of(exc))


def _topic_key(args) -> tuple[str, str]:
    try:
        return current_feature(TopicBrowser).resolve(args)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    except EchoRefused as exc:
        raise _refused(exc) from None


def _seconds(args) -> float:
    raw = args.get("seconds")
    if raw is None:
        return DEFAULT_SECONDS
    try:
        seconds = float(raw)
    except ValueError:
        seconds = math.nan
    if not math.isfinite(seconds) or not 0 < seconds <= MAX_SECONDS:
        raise ApiError(
            400,
            "bad_seconds",
            "seconds must be a number above 0 and at most %(max_seconds)s, not %(raw)s",
            max_seconds=format(MAX_SECONDS, ".0f"),
            raw=repr(raw[:20]),
        )
    return seconds


@bp.get("/api/plot")
def api_plot():
    refuse_cross_site()  # it creates a series and its subscription
    args = request.args
    field = args.get("field", "")
    seconds = _seconds(args)
    key = _topic_key(args)
    plots = current_feature(Plots)
    try:
        series = plots.series(key, field, client_key())
    except NotPlottable as exc:
        raise ApiError(422, "not_plottable", text_of(exc)) from None
    except FieldError as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    except TooManySeries as exc:
        raise ApiError(503, "too_many_series", text_of(exc)) from None
    except EchoRefused as exc:
        raise _refused(exc) from None
    t, v, decimated = series.ring.window(time.time() - seconds)
    return jsonify({"id": series_id(key[0], field), "topic": key[0], "type": key[1], "field": field,
                    "seconds": seconds, "t": t, "v": v, "decimated": decimated,
                    "skipped_nonfinite": series.ring.skipped_nonfinite, "skipped_oversize": oversize(plots, key),
                    "idle_s": plots.idle_s})


@bp.get("/api/plot/fields")
def api_plot_fields():
    topic, type_name = _topic_key(request.args)
    try:
        check_plottable(type_name)
    except NotPlottable as exc:
        raise ApiError(422, "not_plottable", text_of(exc)) from None
    return jsonify({"topic": topic, "type": type_name, "fields": msgs.numeric_paths(type_name)})


@bp.get("/plot")
def plot_page():
    browser = current_feature(TopicBrowser)
    plots = current_feature(Plots)
    return render_template("plot.html", graph=browser.snapshot(), active=plots.active(), idle_s=plots.idle_s)
