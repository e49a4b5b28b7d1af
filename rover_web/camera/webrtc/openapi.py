"""WHEP routes, for GET /api/openapi.json (see rover_web/apidocs/describe.py)."""

from rover_web.apidocs.describe import BODY_ERRORS, obj, op, path
from rover_web.camera.openapi import BAD, PARAMS

WHEP_PARAMS = [p for p in PARAMS if p["name"] in ("topic", "width", "height", "qos_profile", "msg_type")]

_offer = op("WHEP: answer an SDP offer with the camera's video (and the teleop data channel)", tag="camera",
            status=201, media="application/sdp", ok={"type": "string"}, params=WHEP_PARAMS,
            errors={**BODY_ERRORS, 400: BAD + ", bad_sdp, no_video, no_usable_candidates, cannot_subscribe",
                    404: "unknown_topic",
                    503: "too_many_webrtc_viewers (use GET /stream), too_many_producers, too_many_streams, "
                         "webrtc_timeout, shutting_down"},
            description="The body is the SDP offer (Content-Type: application/sdp) with a recvonly video section "
                        "and, for driving, a data channel labelled `teleop`. Candidates are gathered before "
                        "answering (no trickle). The Location header names the session; DELETE it to end.",
            fuzz="skip", fuzz_why="an SDP body; its refusals have their own tests (tests/integration/camera/webrtc)",
            extra={"requestBody": {"required": True, "content": {"application/sdp": {"schema": {"type": "string"}}}}})
_offer["responses"]["201"]["headers"] = {"Location": {"schema": {"type": "string"},
                                                      "description": "/api/camera/whep/<session id>"}}

PATHS = {
    "/api/camera/whep": {
        "post": _offer,
        "get": op("The WebRTC sessions (without their ids)", tag="camera", ok=obj(closed=False)),
    },
    "/api/camera/whep/{session_id}": {
        "delete": op("WHEP: end a session", tag="camera", status=204, ok={},
                     params=[path("session_id", {"type": "string", "maxLength": 64}, "from the Location header")],
                     errors={404: "unknown_session"}),
    },
}
