"""GET and PUT /api/geofence: the fence as a GeoJSON FeatureCollection."""

from __future__ import annotations

from flask import Blueprint, jsonify

from rover_web.core.state import current_feature
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
    return jsonify(current_feature(GeofenceService).replace(json_body()))


@bp.errorhandler(InvalidInput)
def _invalid(exc: InvalidInput):
    return error_response(400, exc.code, str(exc))


def outside_geofence_response(exc: OutsideGeofence):
    """422 for a waypoint, leg or goal the fence refuses; other features' error handlers use it."""
    response = jsonify({"error": "outside_geofence", "message": str(exc), **exc.details})
    response.status_code = 422
    return response
