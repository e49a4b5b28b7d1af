"""GET /api/estop (the latch), POST /api/estop ({"engaged": true|false}), POST /api/estop/all, and
POST /login/estop (the sign-in page's engage-only button)."""

from __future__ import annotations

from flask import Blueprint, abort, jsonify, make_response, render_template, request
from flask_babel import gettext

from rover_web.auth import require_role, signed_in_name
from rover_web.core.state import current_feature, current_rover
from rover_web.web.api_messages import explain, text_of
from rover_web.web.http import ApiError, accepts_form, error_response, json_body, too_many
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
    response = error_response(409, "estop_engaged", text_of(exc))
    return response


@bp.get("/api/estop")
def estop_state():
    estop = current_feature(EStopService)
    return jsonify({**estop.state(), "cancellable_actions": estop.cancellable_actions()})


@bp.post("/api/estop/all")
def estop_all():
    """Engage every robot's e-stop (the "Stop all" button); releasing stays one robot at a time.

    Takes the body POST /api/estop engages with, `{"engaged": true}`, and an empty one; a release
    here is refused: releasing every robot at once would let robots move whose surroundings
    nobody looked at.
    """
    body = json_body(required=False)
    if body.get("engaged") is True:  # as POST /api/estop: engaging works whatever else the body says
        return _engage_all(client_name(body.get("by")))
    try:
        only_keys(body, {"engaged", "by"})
        engaged = body.get("engaged", True)
        if engaged is False:
            raise ApiError(400, "release_per_robot", "releasing is per robot: POST {\"engaged\": false} to "
                           "/robots/<name>/api/estop (or /api/estop with one robot); this route only engages")
        if engaged is not True:
            raise InvalidInput("'engaged' must be true (this route only engages)", "bad_type")
        by = text(body, "by", max_len=NAME_MAX_LEN, default=None)
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    return _engage_all(client_name(by))


@bp.post("/login/estop")
@accepts_form
def login_estop():
    """The sign-in page's e-stop: engages every robot, for anyone who can reach the page, signed in
    or not (docs/security.md#the-sign-in-pages-e-stop). It never releases, and takes no input but
    the request itself: who is the client's address. The Host and Origin guard applies as to
    every POST."""
    if not current_rover().config["ROVER_WEB_LOGIN_ESTOP"]:
        abort(404)
    address = request.remote_addr or "unknown"
    fleet_estop = current_feature(FleetEStop)
    wait_s = fleet_estop.public_engages.hit(address)
    as_json = request.mimetype == "application/json"
    # The limit only bounds presses that change nothing (every robot already stopped): it must
    # never stand between a person and a stop, and the address may be shared (a NAT, a proxy
    # without ROVER_WEB_PROXY_HOPS) with someone who spent it first.
    if wait_s > 0 and fleet_estop.all_engaged:
        if as_json:
            raise too_many(explain("e-stop engages from the sign-in page, and every robot is already engaged"), wait_s)
        return _login_page(429, gettext("every robot's e-stop is already engaged, and this address pressed too "
                                        "often: try again in %(seconds)s s", seconds=round(wait_s)),
                           retry_after_s=wait_s)
    response = _engage_all(f"sign-in page ({address})"[:NAME_MAX_LEN])
    if as_json:
        return response
    return _login_page(200, gettext("E-stop engaged on every robot. Releasing it needs an operator to sign in."))


@bp.post("/estop")
@accepts_form
def estop_form():
    """The header's E-STOP as a plain form (templates/partials/estop.html): it engages before the
    page's scripts have run, on a slow link, or with scripts off. Engage only, under the rules of
    POST /api/estop {"engaged": true}: the guard's Origin check, any signed-in user. The answer is a
    page that says the robot is stopped, with the way back to the page the form was on."""
    estop = current_feature(EStopService)
    back = request.form.get("back", "") if request.mimetype != "application/json" else ""
    # Only a path of this app: never an address elsewhere (//host or a scheme).
    if not back.startswith("/") or back.startswith("//") or "\\" in back or len(back) > 2000:
        back = "/"
    state = estop.engage(client_name(None), via="form")
    html = render_template("estop_engaged.html", engaged_state=state, back=request.script_root + back)
    return make_response(html, 200, {"Content-Type": "text/html; charset=utf-8"})


def _login_page(status: int, notice: str, retry_after_s: float | None = None):
    html = render_template("login.html", next=request.script_root + "/", error=None, username="", login_estop=True,
                           estop_notice=notice)
    response = make_response(html, status, {"Content-Type": "text/html; charset=utf-8"})
    if retry_after_s is not None:
        response.headers["Retry-After"] = str(max(1, int(retry_after_s + 0.999)))
    return response


def _engage_all(by: str):
    robots = current_feature(FleetEStop).engage_all(by)
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
        raise ApiError(400, exc.code, text_of(exc)) from None
    require_role("operator")  # anyone may stop the robot; only an operator may let it move again
    try:
        return jsonify(estop.release(client_name(by)))
    except ReleaseRefused as exc:
        raise ApiError(exc.status, exc.code, text_of(exc)) from None
