"""The replay view's page and data routes, and the upload of a file from elsewhere.

Every data route is a GET over one recording's file (viewer), answered from its chunk map
(file_index.py) and bounded (timeline.py, replay_data.py say how); none publishes anything or
touches the robot. The upload is an operator's (upload.py says why).
"""

from __future__ import annotations

import math

from flask import Response, jsonify, render_template, request

from rover_web.core.state import current_feature
from rover_web.plot.field import FieldError
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, accepts_media, body_limit, error_response
from rover_web.web.validate import InvalidInput, topic_name

from . import replay_data, upload
from .file_index import FileIndex, index_of
from .reading import NotARecording, Refused
from .routes import MAX_NAME, _by, _id, _service, bp
from .service import MB
from .timeline import timeline_of

FRAME_MAX_AGE_S = 300  # a finished file never changes: the same question has the same answer


def _readable(recording_id: str) -> FileIndex:
    service = _service()
    status = service.status(_id(recording_id))
    if status["state"] == "recording":
        raise ApiError(409, "recording_in_progress", "the file is still being written: stop the recording first")
    try:
        # A summary is believed only in a file this server recorded itself (bounds.py, issue 40).
        return index_of(service.path_of(recording_id), trust_summary=status["source"] == "recorded")
    except Refused as exc:
        raise ApiError(422, exc.code, text_of(exc)) from None
    except NotARecording as exc:
        raise ApiError(422, "not_a_recording", text_of(exc)) from None


def _topic() -> str:
    try:
        return topic_name(request.args.get("topic"), "topic")
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None


def _time() -> float:
    raw = request.args.get("t", "")
    try:
        t = float(raw)
    except ValueError:
        t = math.nan
    if not math.isfinite(t) or not 0 <= t < 1e11:
        raise ApiError(400, "bad_time", "t is the time to show, in seconds since the epoch (as the timeline's start "
                                        "and end), not %(raw)s", raw=repr(raw[:30]))
    return t


def _int_arg(name: str, code: str, low: int, high: int, default: int | None) -> int | None:
    raw = request.args.get(name)
    if raw is None or raw == "":
        return default
    if not raw.isdigit() or not low <= int(raw) <= high:
        raise ApiError(400, code, "%(name)s is a whole number from %(low)s to %(high)s, not %(raw)s",
                       name=name, low=low, high=high, raw=repr(raw[:20]))
    return int(raw)


@bp.errorhandler(Refused)
def _refused(exc: Refused):
    """A file over one of bounds.py's bounds, met while answering (a chunk the index did not open)."""
    return error_response(422, exc.code, text_of(exc))


def _not_shown(exc: replay_data.NotShown) -> ApiError:
    return ApiError(404 if exc.code == "unknown_topic" else 422, exc.code, text_of(exc))


@bp.get("/recordings/<recording_id>/replay")
def replay_page(recording_id: str):
    """The replay view: a time slider over the recording's track, LiveMap, plots, diagnostics,
    camera, logs and audit trail, all read from the file; it publishes nothing."""
    from rover_web.livemap.routes import map_summary
    from rover_web.livemap.service import LiveMapService
    from rover_web.waypoints.service import WaypointsService

    rover = _service().rover
    status = _service().status(_id(recording_id))
    livemap = current_feature(LiveMapService)
    config = rover.config
    replay = {
        "id": status["id"], "source": status["source"],
        "maps": [map_summary(d) for d in livemap.files.values()], "default_map": livemap.default_name,
        "pose_topic": rover.resolve(config["ROVER_WEB_AMCL_POSE_TOPIC"]),
        "goal_topic": rover.resolve(config["ROVER_WEB_GOAL_TOPIC"]),
        "plan_topic": rover.resolve(config["ROVER_WEB_PLAN_TOPIC"]),
        "camera_topic": rover.resolve(config["ROVER_WEB_CAMERA_TOPIC"]),
        "bot_diameter_cm": config["ROVER_WEB_LIVEMAP_BOT_DIAMETER_CM"],
        "pose_stale_s": config["ROVER_WEB_LIVEMAP_POSE_STALE_S"],
    }
    # The waypoints map's own settings and offline basemap: the GPS track shows where the robot was.
    return render_template("recording_replay.html", recording=status, replay=replay,
                           map_config=current_feature(WaypointsService).map_config())


@bp.get("/api/recordings/<recording_id>/timeline")
def recording_timeline(recording_id: str):
    index = _readable(recording_id)
    try:
        return jsonify(id=recording_id, **timeline_of(index))
    except Refused as exc:
        raise ApiError(422, exc.code, text_of(exc)) from None
    except NotARecording as exc:
        raise ApiError(422, "not_a_recording", text_of(exc)) from None


@bp.get("/api/recordings/<recording_id>/fields")
def recording_fields(recording_id: str):
    index = _readable(recording_id)
    try:
        return jsonify(replay_data.fields(index, _topic()))
    except replay_data.NotShown as exc:
        raise _not_shown(exc) from None


@bp.get("/api/recordings/<recording_id>/series")
def recording_series(recording_id: str):
    index = _readable(recording_id)
    topic = _topic()
    fields = request.args.getlist("field")
    if not 1 <= len(fields) <= replay_data.MAX_FIELDS or len(set(fields)) != len(fields):
        raise ApiError(400, "bad_field", "give 1 to %(max_fields)s different fields "
                                         "(field=pose.pose.position.x&field=...)", max_fields=replay_data.MAX_FIELDS)
    try:
        return jsonify(replay_data.series(index, topic, fields))
    except FieldError as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    except replay_data.NotShown as exc:
        raise _not_shown(exc) from None


@bp.get("/api/recordings/<recording_id>/diagnostics")
def recording_diagnostics(recording_id: str):
    index = _readable(recording_id)
    stale_s = _service().rover.config["ROVER_WEB_DIAGNOSTICS_STALE_S"]
    return jsonify(replay_data.diagnostics_at(index, _time(), stale_s))


@bp.get("/api/recordings/<recording_id>/frame")
def recording_frame(recording_id: str):
    index = _readable(recording_id)
    topic, t = _topic(), _time()
    config = _service().rover.config
    biggest = config["ROVER_WEB_CAMERA_MAX_DIMENSION"]
    quality = _int_arg("quality", "bad_quality", 1, 100, config["ROVER_WEB_CAMERA_QUALITY"])
    width = _int_arg("width", "bad_width", 16, biggest, None)
    height = _int_arg("height", "bad_height", 16, biggest, None)
    try:
        found = replay_data.frame_at(index, topic, t, quality, width, height, biggest * biggest)
    except replay_data.NotShown as exc:
        raise _not_shown(exc) from None
    if found is None:  # before the topic's first frame: nothing to show yet, which is not an error
        response = Response(status=204)
    else:
        jpeg, logged = found
        response = Response(jpeg.data, mimetype="image/jpeg")
        response.headers["X-Frame-Time"] = f"{logged:.9f}"
        if jpeg.error:
            response.headers["X-Frame-Error"] = jpeg.error_code or "bad_image"
    response.headers["Cache-Control"] = f"private, max-age={FRAME_MAX_AGE_S}"
    return response


@bp.post("/api/recordings/upload")
@accepts_media("application/octet-stream")
@body_limit(lambda config: int(config["ROVER_WEB_RECORDING_UPLOAD_MAX_MB"] * MB))
def upload_recording():
    name = request.args.get("name", "").strip()
    if len(name) > MAX_NAME or any(ord(c) < 32 for c in name):
        raise ApiError(400, "bad_name", "'name' is text of at most %(max_name)s characters, on one line",
                       max_name=MAX_NAME)
    status = upload.receive(_service(), request, name, _by())
    response = jsonify(status)
    response.status_code = 201
    return response


# --- TF: the recording's frames (rover_web/tf/replay.py) ---


def _tf_time(index: FileIndex) -> int:
    """?t= (seconds since the epoch) as ns; absent: the recording's end."""
    if request.args.get("t", "") == "":
        return index.end_ns or 0
    return int(round(_time() * 1e9))


def _tf_tree(recording_id: str) -> tuple[FileIndex, int, dict]:
    from rover_web.tf.replay import tree_at

    index = _readable(recording_id)
    config = _service().rover.config
    t_ns = _tf_time(index)
    return index, t_ns, tree_at(index, t_ns, config["ROVER_WEB_TF_CACHE_S"], config["ROVER_WEB_TF_STALE_S"])


@bp.get("/recordings/<recording_id>/tf")
def recording_tf_page(recording_id: str):
    """The TF page for a recording: its frames at ?t= (the end by default), read from the file."""
    status = _service().status(_id(recording_id))
    _index, t_ns, tree = _tf_tree(recording_id)
    return render_template("recording_tf.html", recording=status, tf=tree, tf_replay=True,
                           tf_lookup_url=f"/api/recordings/{status['id']}/tf/lookup?t={t_ns / 1e9:.9f}")


@bp.get("/api/recordings/<recording_id>/tf")
def recording_tf(recording_id: str):
    return jsonify(_tf_tree(recording_id)[2])


@bp.get("/api/recordings/<recording_id>/tf/lookup")
def recording_tf_lookup(recording_id: str):
    from rover_web.tf.replay import cached_buffer_at
    from rover_web.tf.routes import lookup_response

    index = _readable(recording_id)
    buffer, _info = cached_buffer_at(index, _tf_time(index), _service().rover.config["ROVER_WEB_TF_CACHE_S"])
    return lookup_response(buffer)
