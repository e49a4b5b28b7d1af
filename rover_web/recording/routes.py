"""The recordings' REST API. Viewers list and download, operators record, admins delete
(rover_web/auth/policy.py decides by method, and names the DELETE an admin endpoint). The replay
view's page, its data routes and the upload are in replay_routes.py, on the same blueprint."""

from __future__ import annotations

import re

from flask import Blueprint, jsonify, render_template, request, send_file

from rover_web.auth import signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import ApiError, json_body
from rover_web.web.validate import InvalidInput, only_keys, topic_name

from .service import RecordingService, Selection

bp = Blueprint("recording", __name__)

ID_RE = re.compile(r"[0-9A-Za-z-]{1,64}\Z")
MAX_TOPICS = 500
MAX_NAME = 80


def _service() -> RecordingService:
    return current_feature(RecordingService)


def _by() -> str:
    return signed_in_name() or request.remote_addr or "unknown"  # with sign-in off, the address


def _id(recording_id: str) -> str:
    if not ID_RE.match(recording_id):
        raise ApiError(404, "not_found", "no such recording")
    return recording_id


def parse_selection(body: dict) -> Selection:
    """The start request's body; ApiError(400) naming the field for anything else."""
    try:
        only_keys(body, {"topics", "camera", "name"})
    except InvalidInput as exc:
        raise ApiError(400, exc.code, text_of(exc)) from None
    topics = body.get("topics", "all")
    if isinstance(topics, str):
        if topics != "all" and not (topics.startswith("preset:") and len(topics) > len("preset:")):
            raise ApiError(400, "bad_topics", "'topics' is \"all\", \"preset:NAME\" or a list of topic names")
    elif isinstance(topics, list):
        if not topics or len(topics) > MAX_TOPICS:
            raise ApiError(400, "bad_topics", "'topics' as a list holds 1 to %(max_topics)s topic names",
                           max_topics=MAX_TOPICS)
        try:
            topics = list(dict.fromkeys(topic_name(t, "topics") for t in topics))
        except InvalidInput as exc:
            raise ApiError(400, exc.code, text_of(exc)) from None
    else:
        raise ApiError(400, "bad_topics", "'topics' is \"all\", \"preset:NAME\" or a list of topic names")
    camera = body.get("camera", False)
    if not isinstance(camera, bool):
        raise ApiError(400, "bad_type", "'camera' is true or false")
    name = body.get("name", "")
    if not isinstance(name, str) or len(name) > MAX_NAME or any(ord(c) < 32 for c in name):
        raise ApiError(400, "bad_name", "'name' is text of at most %(max_name)s characters, on one line",
                       max_name=MAX_NAME)
    return Selection(topics, camera, name.strip())


@bp.get("/recordings")
def recordings_page():
    """Start and stop (operators), the list with downloads (viewers); static/js/recording/."""
    service = _service()
    return render_template("recordings.html", presets=sorted(service.presets),
                           upload_max_mb=service.upload_max_bytes / (1024 * 1024))


@bp.get("/api/recordings")
def list_recordings():
    service = _service()
    return jsonify(recordings=service.list(), presets=sorted(service.presets))


@bp.post("/api/recordings")
def start_recording():
    selection = parse_selection(json_body())
    response = jsonify(_service().start(selection, _by()))
    response.status_code = 201
    return response


@bp.get("/api/recordings/<recording_id>")
def recording_status(recording_id: str):
    return jsonify(_service().status(_id(recording_id)))


@bp.post("/api/recordings/<recording_id>/stop")
def stop_recording(recording_id: str):
    return jsonify(_service().stop(_id(recording_id), _by()))


@bp.get("/api/recordings/<recording_id>/file")
def recording_file(recording_id: str):
    service = _service()
    status = service.status(_id(recording_id))
    if status["state"] == "recording":
        raise ApiError(409, "recording_in_progress", "the file is still being written: stop the recording first")
    path = service.path_of(recording_id)
    if not path.is_file():
        raise ApiError(404, "not_found", "the recording's file is gone")
    # conditional=True: Range requests (206), If-Range, ETag; a viewer such as Foxglove can seek remotely.
    return send_file(path, mimetype="application/octet-stream", as_attachment=True,
                     download_name=f"{recording_id}.mcap", conditional=True, max_age=0)


@bp.delete("/api/recordings/<recording_id>")
def delete_recording(recording_id: str):
    _service().delete(_id(recording_id), _by())
    return jsonify(deleted=recording_id)
