"""GET /stream (MJPEG), GET /snapshot (one JPEG) and GET /api/camera/streams (who watches what)."""

from __future__ import annotations

from flask import Blueprint, Response, jsonify, request

from rover_web.auth import signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.connection import peer_gone
from rover_web.web.http import ApiError, error_response, too_many
from rover_web.web.streams import once, opening, refuse_cross_site
from rover_web.web.validate import InvalidInput

from .mjpeg import MIMETYPE, OPENING, multipart_part
from .service import CameraStreams, CannotSubscribe, StreamRefused, Unavailable, UnknownTopic
from .stream import StreamClosed

bp = Blueprint("camera", __name__)

# How often a stream with no new frame checks that its browser is still there.
LIVENESS_CHECK_S = 1.0
NO_CACHE = {"Cache-Control": "no-cache, no-store, must-revalidate", "Pragma": "no-cache", "Expires": "0"}

STATUS = {UnknownTopic: 404, Unavailable: 503, CannotSubscribe: 400}


@bp.errorhandler(InvalidInput)
def invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, str(exc))


@bp.errorhandler(StreamRefused)
def stream_refused(exc: StreamRefused):
    return error_response(STATUS[type(exc)], exc.code, str(exc))


@bp.get("/stream")
def stream():
    streams = current_feature(CameraStreams)
    with opening("mjpeg") as slot:
        key = streams.key_for(request.args)
        producer = streams.acquire(key, slot.client)
    release = once(lambda: streams.release(key, slot.client), slot.release)

    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    stopping = streams.rover.stopping

    def frames():
        yield OPENING  # headers go out now, not at the first frame
        seq = 0
        while not stopping.is_set():
            try:
                got = producer.next_frame(seq, LIVENESS_CHECK_S)
            except StreamClosed:
                return
            if got is None:
                if peer_gone(sock):
                    return
                continue
            seq, jpeg = got
            yield multipart_part(jpeg)

    response = Response(frames(), mimetype=MIMETYPE, headers={**NO_CACHE, "X-Accel-Buffering": "no"})
    # WSGI servers call close() however the response ends (done, browser gone, error), even if
    # the generator never started, so the viewer is always released exactly once.
    response.call_on_close(release)
    return response


@bp.get("/snapshot")
def snapshot():
    refuse_cross_site()
    streams = current_feature(CameraStreams)
    wait = streams.snapshots.hit(signed_in_name() or request.remote_addr or "")
    if wait:  # each one may subscribe and decode: one client's loop must not cost everyone's frames
        raise too_many("snapshot requests (ROVER_WEB_CAMERA_SNAPSHOTS_PER_MIN)", wait)
    key = streams.key_for(request.args)
    producer = streams.acquire(key)
    try:
        try:
            got = producer.next_frame(0, streams.snapshot_timeout_s)
        except StreamClosed:
            raise ApiError(503, "shutting_down", "the server is shutting down") from None
    finally:
        streams.release(key)
    if got is None:
        raise ApiError(504, "no_frame", f"no image arrived on {key.topic} within {streams.snapshot_timeout_s:g} s "
                                        f"(QoS {key.qos}); is the camera publishing?")
    jpeg = got[1]
    if jpeg.error is not None:
        status = 415 if jpeg.error_code == "unsupported_encoding" else 422
        raise ApiError(status, jpeg.error_code or "bad_image", jpeg.error)
    return Response(jpeg.data, mimetype="image/jpeg",
                    headers={**NO_CACHE, "X-Timestamp": f"{jpeg.stamp:.9f}"})


@bp.get("/api/camera/streams")
def streams_status():
    streams = current_feature(CameraStreams)
    return jsonify(viewers=streams.viewers, streams=streams.describe())
