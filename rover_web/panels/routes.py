"""Pages (/panels, /panels/<panel>) and the API (/api/panels/...) of the control panels."""

from __future__ import annotations

from flask import Blueprint, abort, current_app, jsonify, render_template, request
from flask_babel import gettext

from rover_web.auth import signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, error_response, json_body

from .service import CommandRefused, InvalidCommand, PanelError, PanelService, TooMany, UnknownControl, UnknownPanel

bp = Blueprint("panels", __name__)

MAX_LOG_LIMIT = 500

STATUS = {UnknownPanel: 404, UnknownControl: 404, InvalidCommand: 400, CommandRefused: 409, TooMany: 429}


@bp.errorhandler(PanelError)
def panel_error(exc: PanelError):
    response = error_response(STATUS[type(exc)], exc.code, text_of(exc))
    if isinstance(exc, TooMany):
        response.headers["Retry-After"] = str(max(1, int(exc.retry_after_s + 0.999)))
    return response


def service() -> PanelService:
    return current_feature(PanelService)


def _client() -> str:
    """Who the operator log names: the signed-in user, else (sign-in off) the client's address."""
    return signed_in_name() or request.remote_addr or ""


def _page_panels(panel_ids: list[str]) -> list[dict]:
    svc = service()
    shown = current_app.config["ROVER_WEB_PANELS_LOG_SHOWN"]
    views = svc.views()
    return [{"spec": svc.specs[pid], "view": views[pid], "log": svc.oplog.recent(pid, shown)} for pid in panel_ids]


@bp.get("/panels")
def panels_page():
    svc = service()
    return render_template("control_panels.html", panels=_page_panels(list(svc.specs)), single=None,
                           log_shown=current_app.config["ROVER_WEB_PANELS_LOG_SHOWN"])


@bp.get("/panels/<panel_id>")
def panel_page(panel_id: str):
    svc = service()
    if panel_id not in svc.specs:
        abort(404, gettext("There is no panel %(name)s.", name=repr(panel_id[:40])))
    return render_template("control_panels.html", panels=_page_panels([panel_id]), single=svc.specs[panel_id],
                           log_shown=current_app.config["ROVER_WEB_PANELS_LOG_SHOWN"])


@bp.app_context_processor
def panel_summaries():
    """`panel_summaries()` for the dashboard card, evaluated only where a template calls it."""
    def summaries() -> list[dict]:
        svc = service()
        views = svc.views()
        return [{"spec": spec, "view": views[pid]} for pid, spec in svc.specs.items()]
    return {"panel_summaries": summaries}


@bp.get("/api/panels")
def list_panels():
    svc = service()
    return jsonify(panels=[svc.detail(pid) for pid in svc.specs])


@bp.get("/api/panels/<panel_id>")
def get_panel(panel_id: str):
    return jsonify(service().detail(panel_id))


@bp.get("/api/panels/<panel_id>/log")
def get_log(panel_id: str):
    svc = service()
    svc.panel(panel_id)
    raw = request.args.get("limit", "50")
    try:
        limit = int(raw)
    except ValueError:
        limit = -1
    if not 1 <= limit <= MAX_LOG_LIMIT:
        raise ApiError(400, "bad_limit", "limit must be an integer from 1 to %(max_log_limit)s, got %(raw)s",
                       max_log_limit=MAX_LOG_LIMIT, raw=repr(raw[:20]))
    return jsonify(panel=panel_id, entries=svc.oplog.recent(panel_id, limit))


@bp.post("/api/panels/<panel_id>/unlock")
def unlock(panel_id: str):
    svc = service()
    svc.panel(panel_id)
    json_body(required=False)  # a body, if any, must still be valid JSON
    return jsonify(svc.unlock(panel_id, _client()))


@bp.post("/api/panels/<panel_id>/lock")
def lock(panel_id: str):
    svc = service()
    svc.panel(panel_id)
    json_body(required=False)
    return jsonify(svc.lock(panel_id, _client()))


@bp.post("/api/panels/<panel_id>/<control_id>")
def command(panel_id: str, control_id: str):
    try:
        body: dict | InvalidCommand = json_body(required=False)
    except ApiError as exc:
        if exc.status != 400:
            raise
        body = InvalidCommand(exc.text, exc.code)  # still 404 first for an unknown control, then logged
    return jsonify(service().command(panel_id, control_id, body, _client()))
