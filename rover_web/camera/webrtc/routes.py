"""WHEP (RFC 9725) for the camera: POST an offer, get the answer and a Location; DELETE it to end."""

from __future__ import annotations

from flask import Blueprint, Response, jsonify, request

from rover_web.auth import AuthService, current_identity, may, on_revoke, signed_in_name
from rover_web.camera.service import StreamRefused
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, accepts_media, error_response
from rover_web.web.streams import opening
from rover_web.web.validate import InvalidInput

from .service import WebRtcService

bp = Blueprint("camera_webrtc", __name__)

SDP = "application/sdp"
STATUS = {"unknown_topic": 404, "cannot_subscribe": 400}


@bp.errorhandler(InvalidInput)
def invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


@bp.errorhandler(StreamRefused)
def refused(exc: StreamRefused):
    return error_response(STATUS.get(exc.code, 503), exc.code, text_of(exc))


@bp.post("/api/camera/whep")
@accepts_media(SDP)
def whep_offer():
    if request.mimetype != SDP:
        raise ApiError(415, "unsupported_media_type",
                       "send the SDP offer as the body with the header Content-Type: application/sdp (WHEP)")
    service = current_feature(WebRtcService)
    sign_in = current_feature(AuthService).sign_in_on()
    identity = current_identity()
    # The slot is taken here, in the request, where the client (user or address), its share of the
    # stream cap and whether it may use the reserve kept for driving are known (web/streams.py).
    with opening("webrtc") as slot:
        session_id, answer = service.open(request.args, request.get_data(as_text=True), user=signed_in_name(),
                                          role=getattr(identity, "role", None), may_operate=may("operator", sign_in),
                                          slot=slot)
    # Its credential is watched from now on: a revoked token, a removed user, a new role or password
    # or a sign-out ends the peer connection, and with it the teleop channel (docs/security.md).
    service.watch(session_id, on_revoke(lambda reason: service.revoke(session_id, reason)))
    response = Response(answer, status=201, mimetype=SDP)
    response.headers["Location"] = f"{request.script_root}/api/camera/whep/{session_id}"
    response.headers["Cache-Control"] = "no-store"
    return response


@bp.delete("/api/camera/whep/<session_id>")
def whep_end(session_id: str):
    service = current_feature(WebRtcService)
    sign_in = current_feature(AuthService).sign_in_on()
    ended = service.end(session_id[:64], signed_in_name() if sign_in else None, admin=may("admin", sign_in))
    if not ended:
        raise ApiError(404, "unknown_session", "no such WebRTC session (it ended, or was never made)")
    return Response(status=204)


@bp.get("/api/camera/whep")
def whep_sessions():
    return jsonify(current_feature(WebRtcService).describe())
