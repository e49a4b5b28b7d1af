"""GET and PUT /api/geofence: the fence as a GeoJSON FeatureCollection. Replacing it is an admin's
work, and goes in the operator log with who did it."""

from __future__ import annotations

from flask import Blueprint, jsonify, request

from rover_web.auth import require_role, signed_in_name
from rover_web.core.state import current_feature
from rover_web.web.api_messages import text_of
from rover_web.web.http import error_response, json_body
from rover_web.web.validate import InvalidInput

from .rules import OutsideGeofence
from .service import GeofenceService

bp = Blueprint("geofence", __name__)


@bp.get("/api/geofence")
def get_fence():
    return jsonify(current_feature(GeofenceService).collection())


@bp.put("/api/geofence")
def put_fence():
    # Admin work: emptying the fence takes away the server's keep-in and keep-out checks on every
    # waypoint, mission and goal (issue 27). The view decides, as the e-stop's release does.
    require_role("admin")
    by = signed_in_name() or request.remote_addr or "unknown"  # with sign-in off, the address
    return jsonify(current_feature(GeofenceService).replace(json_body(), by=by))


@bp.errorhandler(InvalidInput)
def _invalid(exc: InvalidInput):
    return error_response(400, exc.code, text_of(exc))


def outside_geofence_response(exc: OutsideGeofence):
    """422 for a waypoint, leg or goal the fence refuses; other features' error handlers use it."""
    response = jsonify({"error": "outside_geofence", "message": str(exc), **exc.details})
    response.status_code = 422
    return response
