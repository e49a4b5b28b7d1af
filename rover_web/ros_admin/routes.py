"""The /ros page and the node, parameter, service and action API (see docs/ros_admin.md)."""

from __future__ import annotations

import json
import time

from flask import Blueprint, Response, jsonify, render_template, request
from flask_babel import gettext

from rover_web.auth import AuthService, may, signed_in_name
from rover_web.core.state import current_feature, current_rover
from rover_web.web.api_messages import text_of
from rover_web.web.connection import peer_gone
from rover_web.web.http import ApiError, error_response, json_body
from rover_web.web.streams import once, opening
from rover_web.web.validate import InvalidInput, number, only_keys, topic_name

from .names import goal_id as valid_goal_id
from .names import node_name
from .parameters import PARAMETER_NAME
from .secret_params import hide_parameters
from .service import AdminRefused, RosAdmin

bp = Blueprint("ros_admin", __name__)

MAX_SERVICE_TIMEOUT_S = 60.0
DEFAULT_SERVICE_TIMEOUT_S = 5.0


@bp.errorhandler(AdminRefused)
def refused(exc: AdminRefused):
    return error_response(exc.status, exc.code, text_of(exc))


@bp.errorhandler(InvalidInput)
def invalid(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


READ_METHODS = frozenset({"GET", "HEAD", "OPTIONS"})
# Canceling a goal sent from here only stops it: allowed in read-only mode too, as the e-stop is.
STOPS_ONLY = frozenset({"ros_admin.api_cancel_goal"})


@bp.before_request
def check_mode():
    """ROVER_WEB_ROS_ADMIN: off refuses everything here, read-only every write."""
    admin = current_feature(RosAdmin)
    if admin.mode == "off":
        if request.endpoint == "ros_admin.ros_page":
            return render_template("ros.html", off=True, nodes=[], services=[], goals=[]), 403
        raise ApiError(403, "ros_admin_off", "ROS admin is off on this server (ROVER_WEB_ROS_ADMIN=off): "
                       "no node's parameters, services or actions are reached from here")
    if admin.mode == "read-only" and request.method not in READ_METHODS and request.endpoint not in STOPS_ONLY:
        raise ApiError(403, "ros_admin_read_only", "ROS admin is read-only on this server "
                       "(ROVER_WEB_ROS_ADMIN=read-only): parameters, services and goals are shown, never sent")
    return None


def _is_admin() -> bool:
    """Whether this request may write (the admin role; anyone with sign-in off, as for every route)."""
    return may("admin", current_feature(AuthService).sign_in_on())


def _write_block() -> str | None:
    """Why this page's user may not set, call or send, or None: for disabled buttons (the server decides).
    In the page's language: only the page shows it."""
    admin = current_feature(RosAdmin)
    if admin.mode == "read-only":
        return gettext("ROS admin is read-only on this server (ROVER_WEB_ROS_ADMIN=read-only)")
    if not _is_admin():
        return gettext("setting parameters, calling services and sending goals needs the admin role")
    return None


def _client() -> str:
    return signed_in_name() or request.remote_addr or ""


def _node(path: str) -> str:
    name = node_name(path)
    if name is None:
        raise ApiError(400, "bad_node_name", "a node name is '/'-separated parts of letters, digits and '_' "
                       "(in the URL without its leading '/': /api/nodes/ns/talker/parameters)")
    return name


def _goal(text: str) -> str:
    goal = valid_goal_id(text)
    if goal is None:
        raise ApiError(400, "bad_goal_id", "a goal id is 32 lowercase hexadecimal digits")
    return goal


@bp.get("/ros")
def ros_page():
    admin = current_feature(RosAdmin)
    nodes = admin.nodes()
    services = [{**s, "refused": admin.service_refusal(s["name"])} for s in admin.services()]
    actions = [{**a, "refused": admin.action_refusal(a["name"], a["types"][0] if a["types"] else "")}
               for n in nodes for a in n["action_servers"]]
    return render_template("ros.html", off=False, nodes=nodes, services=services, actions=actions,
                           goals=[g.snapshot() for g in admin.goals.all()], write_block=_write_block(),
                           can_cancel=may("operator", current_feature(AuthService).sign_in_on()))


@bp.get("/api/nodes")
def api_nodes():
    return jsonify(nodes=current_feature(RosAdmin).nodes())


@bp.get("/api/nodes/<path:node>/parameters")
def api_parameters(node: str):
    name = _node(node)
    admin = current_feature(RosAdmin)
    parameters = [{**p, "refused": admin.parameter_refusal(name, p["name"])} for p in admin.parameters(name)]
    if not _is_admin():
        parameters = hide_parameters(parameters)  # credentials live in parameters: values for admins only
    else:
        parameters = [{**p, "hidden": False} for p in parameters]
    return jsonify(node=name, parameters=parameters, safety_node=admin.is_safety_node(name))


@bp.put("/api/nodes/<path:node>/parameters/<path:name>")
def api_set_parameter(node: str, name: str):
    full = _node(node)
    if not PARAMETER_NAME.match(name):
        raise ApiError(400, "bad_parameter_name", "a parameter name is letters, digits, '_', '.' and '/'")
    body = json_body()
    only_keys(body, {"value"})
    if "value" not in body:
        raise ApiError(400, "missing_field", "'value' is required")
    return jsonify(current_feature(RosAdmin).set_parameter(full, name, body["value"], _client()))


@bp.get("/api/services")
def api_services():
    return jsonify(services=current_feature(RosAdmin).services())


@bp.get("/api/types/<package>/<kind>/<name>")
def api_type(package: str, kind: str, name: str):
    if kind not in ("msg", "srv", "action"):
        raise ApiError(404, "unknown_kind", "the kind is msg, srv or action")
    return jsonify(current_feature(RosAdmin).describe_type(package, kind, name))


@bp.post("/api/services/call")
def api_call_service():
    body = json_body()
    only_keys(body, {"service", "type", "request", "timeout_s"})
    service = topic_name(body.get("service"), "service")
    timeout_s = number(body, "timeout_s", low=0.1, high=MAX_SERVICE_TIMEOUT_S, default=DEFAULT_SERVICE_TIMEOUT_S)
    response = current_feature(RosAdmin).call_service(service, body.get("type"), body.get("request", {}),
                                                      timeout_s, _client())
    return jsonify(service=service, response=response)


@bp.get("/api/actions/goals")
def api_goals():
    return jsonify(goals=[g.snapshot() for g in current_feature(RosAdmin).goals.all()])


@bp.post("/api/actions/goal")
def api_send_goal():
    body = json_body()
    only_keys(body, {"action", "type", "goal"})
    action = topic_name(body.get("action"), "action")
    return jsonify(current_feature(RosAdmin).send_goal(action, body.get("type"), body.get("goal", {}), _client()))


@bp.post("/api/actions/<goal_id>/cancel")
def api_cancel_goal(goal_id: str):
    json_body()  # a state-changing request carries JSON like every other (an empty object is fine)
    return jsonify(current_feature(RosAdmin).cancel_goal(_goal(goal_id), _client()))


@bp.get("/api/ros/log")
def api_log():
    limit = request.args.get("limit", "50")
    if not (limit.isascii() and limit.isdigit()) or not 1 <= int(limit) <= 500:  # '²' is a digit to isdigit
        raise ApiError(400, "bad_limit", "limit is 1 to 500")
    return jsonify(entries=current_feature(RosAdmin).recent(int(limit)))


def _event(name: str, data: dict) -> bytes:
    return f"event: {name}\ndata: {json.dumps(data, allow_nan=False, default=str)}\n\n".encode()


@bp.get("/api/actions/<goal_id>/events")
def api_goal_events(goal_id: str):
    """SSE: `status` first (the whole goal), then `feedback` and `status` as they change, `result` last."""
    rover = current_rover()
    with opening("action_events") as slot:
        tracked = current_feature(RosAdmin).goal(_goal(goal_id))
    release = once(slot.release)
    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    keepalive_s = rover.config["ROVER_WEB_SSE_KEEPALIVE_S"]
    stopping = rover.stopping

    def stream():
        try:
            snap = tracked.snapshot()
            yield f"retry: {rover.config['ROVER_WEB_SSE_RETRY_MS']}\n\n".encode() + _event("status", snap)
            if snap["result"] is not None:  # finished before the stream opened
                yield _event("result", {"goal_id": snap["goal_id"], "status": snap["status"],
                                        "result": snap["result"]})
                return
            seq, feedback_seq, status = snap["seq"], snap["feedback_seq"], snap["status"]
            last_write = time.monotonic()
            while snap["result"] is None and not stopping.is_set():
                if tracked.wait_newer(seq, min(1.0, keepalive_s)) == seq:
                    now = time.monotonic()
                    if now - last_write >= keepalive_s:
                        yield b": keep-alive\n\n"
                        last_write = now
                    elif peer_gone(sock):
                        return
                    continue
                snap = tracked.snapshot()
                out = b""
                if snap["feedback_seq"] != feedback_seq:
                    out += _event("feedback", {"goal_id": snap["goal_id"], "feedback": snap["feedback"]})
                if snap["status"] != status:
                    out += _event("status", {"goal_id": snap["goal_id"], "status": snap["status"]})
                if snap["result"] is not None:
                    out += _event("result", {"goal_id": snap["goal_id"], "status": snap["status"],
                                             "result": snap["result"]})
                seq, feedback_seq, status = snap["seq"], snap["feedback_seq"], snap["status"]
                yield out
                last_write = time.monotonic()
        finally:
            release()

    response = Response(stream(), mimetype="text/event-stream",
                        headers={"Cache-Control": "no-cache", "X-Accel-Buffering": "no"})
    response.call_on_close(release)
    return response
