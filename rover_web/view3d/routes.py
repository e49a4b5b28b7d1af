"""The 3D view: the /3d page, the robot's model, mesh files from package shares, the thinned point cloud."""

from __future__ import annotations

import math
import threading

from flask import Blueprint, Response, jsonify, render_template, request, send_file

from rover_web.auth import on_revoke
from rover_web.core.state import current_feature
from rover_web.web.http import ApiError
from rover_web.web.streams import opening

from .meshes import MeshRefused, resolve
from .service import View3dService

bp = Blueprint("view3d", __name__)

CLOUD_MAX_WAIT_S = 2.0
IMMUTABLE = "public, max-age=31536000, immutable"


@bp.get("/3d")
def view3d_page():
    return render_template("view3d.html", robot=current_feature(View3dService).robot())


@bp.get("/api/3d/robot")
def robot():
    return jsonify(current_feature(View3dService).robot())


@bp.get("/api/3d/mesh/<package>/<path:path>")
def mesh(package: str, path: str):
    try:
        found = resolve(package, path)
    except MeshRefused as exc:
        raise ApiError(exc.status, exc.code, exc.text) from None
    # A package's file does not change while it is installed; a reinstall changes size or mtime, and
    # so the ETag, and a page that reloads the model asks again (If-None-Match answers 304).
    if request.if_none_match.contains(found.etag):
        response = Response(status=304)
    else:
        response = send_file(found.path, mimetype=found.content_type, conditional=False, etag=False,
                             max_age=None)
    response.set_etag(found.etag)
    response.headers["Cache-Control"] = IMMUTABLE
    return response


def _number(name: str, code: str, default: float, low: float, high: float) -> float:
    raw = request.args.get(name)
    if raw is None:
        return default
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or not low <= value <= high:
        raise ApiError(400, code, "%(name)s must be a number from %(low)s to %(high)s, got %(raw)s",
                       name=name, low=format(low, "g"), high=format(high, "g"), raw=repr(raw[:20]))
    return value


@bp.get("/api/3d/cloud")
def cloud():
    """The newest thinned point cloud past sequence `after` (binary, cloud.py's frame), waiting up to
    `wait` seconds for one; 204 when none came. A waiting request holds a stream slot."""
    feature = current_feature(View3dService)
    if not feature.cloud_topic:
        raise ApiError(404, "no_cloud_topic", "no point cloud topic is set (ROVER_WEB_POINTCLOUD_TOPIC)")
    after = int(_number("after", "bad_after", 0, 0, 2**53))
    wait_s = _number("wait", "bad_wait", 0, 0, CLOUD_MAX_WAIT_S)
    if wait_s > 0:
        ended = threading.Event()
        with opening("view3d_cloud") as slot, on_revoke(lambda _reason: feature.end_waits(ended)):
            try:
                seq, frame = feature.cloud_after(after, wait_s, ended)
            finally:
                slot.release()
        if ended.is_set():
            raise ApiError(401, "revoked", "the credentials this request was made with have ended")
    else:
        seq, frame = feature.cloud_after(after, 0)
    if frame is None:
        response = Response(status=204)
    else:
        response = Response(frame, mimetype="application/octet-stream")
    response.headers["X-Cloud-Seq"] = str(seq)
    response.headers["Cache-Control"] = "no-store"
    return response
