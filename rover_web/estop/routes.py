"""GET /api/estop (the latch), POST /api/estop ({"engaged": true|false}), POST /api/estop/all."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.auth import require_role, signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.validate import InvalidInput, only_keys, text

from .fleet import FleetEStop
from .service import EStopEngaged, EStopService, ReleaseRefused

bp = Blueprint("estop", __name__)

NAME_MAX_LEN = 40


def client_name(raw: object) -> str:
    """Who engaged or released: the signed-in user; else the name the page sent; else the address."""
    signed_in = signed_in_name()
    if signed_in:
        return signed_in
    if isinstance(raw, str):
        name = " ".join(raw.split())[:NAME_MAX_LEN]
        if name and name.isprintable():
            return name
    return request.remote_addr or "unknown"


@bp.app_errorhandler(EStopEngaged)
def estop_engaged(exc: EStopEngaged):
    """Any feature's view that raises EStopEngaged answers the same 409."""
    response = error_response(409, "estop_engaged", str(exc))
    return response


@bp.get("/api/estop")
def estop_state():
    estop = current_feature(EStopService)
    return jsonify({**estop.state(), "cancellable_actions": estop.cancellable_actions()})


@bp.post("/api/estop/all")
def estop_all():
    """Engage every robot's e-stop (the "Stop all" button); releasing stays one robot at a time."""
    body = json_body(required=False)
    try:
        only_keys(body, {"by"})
        by = text(body, "by", max_len=NAME_MAX_LEN, default=None)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, str(exc)) from None
    robots = current_feature(FleetEStop).engage_all(client_name(by))
    return jsonify({"engaged": all(state["engaged"] for state in robots.values()), "robots": robots})


@bp.post("/api/estop")
def estop_set():
    estop = current_feature(EStopService)
    body = json_body()
    if body.get("engaged") is True:  # engaging always works, whatever else the body says
        return jsonify(estop.engage(client_name(body.get("by")), via="api"))
    try:
        only_keys(body, {"engaged", "by"})
        if "engaged" not in body:
            raise InvalidInput("'engaged' is required: true engages the e-stop, false releases it", "missing_field")
        if not isinstance(body["engaged"], bool):
            raise InvalidInput("'engaged' must be true or false", "bad_type")
        by = text(body, "by", max_len=NAME_MAX_LEN, default=None)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, str(exc)) from None
    require_role("operator")  # anyone may stop the robot; only an operator may let it move again
    try:
        return jsonify(estop.release(client_name(by)))
    except ReleaseRefused as exc:
        raise ApiError(exc.status, exc.code, str(exc)) from None
