"""GET /stream (MJPEG), GET /snapshot (one JPEG), GET /api/camera/streams (who watches what),
GET /api/camera/viewers (what each viewer gets) and POST /api/camera/viewers/<id>/ack (what a
page acknowledging its stream has received, acks.py)."""

from __future__ import annotations

import time

from flask import Blueprint, Response, jsonify, request

from rover_web.auth import signed_in_name
from rover_web.core.leases import Closed, Full
from rover_web.core.state import current_feature
from rover_web.web.api_messages import explain, text_of
from rover_web.web.connection import peer_gone
from rover_web.web.http import ApiError, error_response, json_body, too_many
from rover_web.web.streams import once, opening, refuse_cross_site
from rover_web.web.validate import InvalidInput, only_keys

from .acks import AckedStream
from .mjpeg import MIMETYPE, OPENING, multipart_part
from .params import viewer_label, wants_acks
from .rate import Step
from .sendq import queued_bytes
from .service import CameraStreams, CannotSubscribe, Client, StreamRefused, Unavailable, UnknownTopic
from .stream import FrameProducer, StreamClosed, StreamKey

bp = Blueprint("camera", __name__)

# How often a stream with no new frame checks that its browser is still there.
LIVENESS_CHECK_S = 1.0
# How often an adaptive stream re-reads the camera's rate (the frame-rate floor depends on it).
SOURCE_RATE_EVERY_S = 1.0
NO_CACHE = {"Cache-Control": "no-cache, no-store, must-revalidate", "Pragma": "no-cache", "Expires": "0"}

STATUS = {UnknownTopic: 404, Unavailable: 503, CannotSubscribe: 400}


@bp.errorhandler(InvalidInput)
def invalid_input(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


@bp.errorhandler(StreamRefused)
def stream_refused(exc: StreamRefused):
    return error_response(STATUS[type(exc)], exc.code, text_of(exc))


@bp.get("/stream")
def stream():
    streams = current_feature(CameraStreams)
    with opening("mjpeg") as slot:
        key = streams.key_for(request.args)
        label = viewer_label(request.args)
        acks = wants_acks(request.args)
        producer = streams.acquire(key, slot.client)
    client = streams.client(key, label, slot.client, acks_from=signed_in_name() if acks else False)
    # The viewer may move to other outputs of its topic (adaptation): release the one it holds last.
    release = once(lambda: streams.release(client.key, client.owner), slot.release,
                   lambda: streams.client_left(client))

    sock = request.environ.get("werkzeug.socket") or request.environ.get("gunicorn.socket")
    stopping = streams.rover.stopping
    frames = adaptive_frames if client.rate is not None else plain_frames
    headers = {**NO_CACHE, "X-Accel-Buffering": "no"}
    if client.acks is not None:  # with adaptation off there is nothing to acknowledge to: no header
        headers["X-Camera-Viewer"] = client.acks.id
    response = Response(frames(streams, client, producer, sock, stopping), mimetype=MIMETYPE, headers=headers)
    # WSGI servers call close() however the response ends (done, browser gone, error), even if
    # the generator never started, so the viewer is always released exactly once.
    response.call_on_close(release)
    return response


def plain_frames(streams: CameraStreams, client: Client, producer: FrameProducer, sock, stopping):
    """Every frame the camera makes, as asked (ROVER_WEB_CAMERA_ADAPT=false)."""
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
        part = multipart_part(jpeg)
        yield part
        client.meter.sent(len(part), (jpeg.width, jpeg.height), client.key.quality)


def adaptive_frames(streams: CameraStreams, client: Client, producer: FrameProducer, sock, stopping):
    """The freshest frame the viewer's path can carry (rate.py): wait for the pacing interval
    (watching the last frame leave the socket meanwhile), take the newest message at the step
    (quality, size) the rate control chose, wait until the socket has let the last frame go
    down to a small budget, and write the newest frame then. Code after a `yield` runs once the
    server has handed the part to the socket."""
    acks = client.acks
    if acks is not None:
        acks.wrote(len(OPENING))
    yield OPENING
    rate = client.rate
    seq, in_use, base = 0, 0, None  # base: the size of a full-size frame, for the smaller steps
    parts = 0
    checked = time.monotonic()
    rate_read = -SOURCE_RATE_EVERY_S

    def queued() -> int:
        """What stands between the server and the viewer: the socket's queue, or for an
        acknowledging page what it has not received yet, whichever is more (acks.py)."""
        socket = queued_bytes(sock)
        return (socket or 0) if acks is None else acks.queued(socket)

    def gone() -> bool:
        return peer_gone(sock) or stalled(acks)

    def wait(seconds: float) -> bool:
        """False when the stream must end (shutdown, the browser went away, or its page stopped
        acknowledging)."""
        nonlocal checked
        now = time.monotonic()
        if stalled(acks):
            return False
        if now - checked >= LIVENESS_CHECK_S:
            checked = now
            if peer_gone(sock):
                return False
        return not stopping.wait(min(seconds, 0.05))

    while not stopping.is_set():
        pause = rate.pace_s(queued)
        if pause > 0:
            if not wait(pause):
                return
            continue
        wanted = output_key(client.asked, rate.step, base)
        if wanted != client.key:
            try:
                producer = streams.switch(client.key, wanted, client.owner)
                client.key, in_use = wanted, rate.index
            except (Full, Closed):
                rate.refused(rate.index)
        now = time.monotonic()
        if now - rate_read >= SOURCE_RATE_EVERY_S:
            rate_read = now
            rate.source_fps = producer.arrivals.snapshot(stale_after_s=2.0)["rate_hz"] or None
        try:
            got = producer.next_frame(seq, LIVENESS_CHECK_S)
            if got is None:
                checked = time.monotonic()
                if gone():
                    return
                continue
            held = False
            while (hold := rate.hold_s(queued())) > 0:
                held = True
                if not wait(hold):
                    return
            if held:  # a newer message may have come while the socket drained: send that one
                got = producer.next_frame(got[0], 0.0) or got
        except StreamClosed:
            return
        seq, jpeg = got
        if in_use == 0 and jpeg.error is None:
            base = (jpeg.width, jpeg.height)
        if acks is None:
            part = multipart_part(jpeg)
        else:
            parts += 1
            part = multipart_part(jpeg, parts)
        started, before = time.monotonic(), queued()
        if acks is not None:
            acks.wrote(len(part))  # before the write: the page may acknowledge it before the yield returns
        yield part
        rate.sent(len(part), started, before, size=(jpeg.width, jpeg.height), step_index=in_use)


def stalled(acks: AckedStream | None) -> bool:
    """An acknowledging page that has said nothing for ACK_STALL_S with bytes outstanding is ended
    (its page reconnects): it must not hold a stream and a thread for ever."""
    return acks is not None and acks.stalled()


def output_key(asked: StreamKey, step: Step, base: tuple[int, int] | None) -> StreamKey:
    """The output (shared by every viewer on the same step) for `step` of what was asked."""
    if step.scale == 1.0 or base is None:
        return asked._replace(quality=step.quality)
    return asked._replace(width=max(1, round(base[0] * step.scale)), height=max(1, round(base[1] * step.scale)),
                          quality=step.quality)


@bp.get("/snapshot")
def snapshot():
    refuse_cross_site()
    streams = current_feature(CameraStreams)
    wait = streams.snapshots.hit(signed_in_name() or request.remote_addr or "")
    if wait:  # each one may subscribe and decode: one client's loop must not cost everyone's frames
        raise too_many(explain("snapshot requests (ROVER_WEB_CAMERA_SNAPSHOTS_PER_MIN)"), wait)
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
        raise ApiError(504, "no_frame", "no image arrived on %(topic)s within %(snapshot_timeout_s)s s (QoS "
                                        "%(qos)s); is the camera publishing?",
                       topic=key.topic, snapshot_timeout_s=format(streams.snapshot_timeout_s, "g"), qos=key.qos)
    jpeg = got[1]
    if jpeg.error is not None:
        status = 415 if jpeg.error_code == "unsupported_encoding" else 422
        raise ApiError(status, jpeg.error_code or "bad_image", jpeg.error_text)
    return Response(jpeg.data, mimetype="image/jpeg",
                    headers={**NO_CACHE, "X-Timestamp": f"{jpeg.stamp:.9f}"})


@bp.get("/api/camera/streams")
def streams_status():
    streams = current_feature(CameraStreams)
    return jsonify(viewers=streams.viewers, streams=streams.describe())


@bp.post("/api/camera/viewers/<viewer_id>/ack")
def viewer_ack(viewer_id: str):
    """The page of an acknowledged stream has received `bytes` body bytes on it in all."""
    streams = current_feature(CameraStreams)
    acked = streams.acked.find(viewer_id[:64], signed_in_name())
    if acked is None:  # unknown, ended, or another identity's: the same answer, so ids are not revealed
        raise ApiError(404, "unknown_viewer", "no such acknowledged camera stream (it ended, or was never "
                                              "opened by you); open GET /stream?ack=1 again")
    body = json_body()
    only_keys(body, {"bytes"})
    if "bytes" not in body:
        raise InvalidInput("'bytes' is required: the body bytes received on the stream in all", "missing_field")
    acked.ack(body["bytes"])
    return Response(status=204)


@bp.get("/api/camera/viewers")
def viewers_status():
    """What each /stream viewer gets: fps, size, kbit/s, and the rate control's view of its path."""
    streams = current_feature(CameraStreams)
    return jsonify(adapt=streams.adapt, viewers=streams.clients(viewer_label(request.args)))
