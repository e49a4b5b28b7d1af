"""The geofence: areas the robot must stay in (keep_in) or out of (keep_out), enforced by the server.

HTTP (routes.py):
  GET /api/geofence    the fence, a GeoJSON FeatureCollection (plus its `revision`)
  PUT /api/geofence    replace it whole (admin; an operator-log line names who); invalid GeoJSON,
                       self-intersecting rings, too many vertices or the antimeridian -> 400, nothing changed
SSE: `geofence`, the robot's side of the fence (inside, outside, unknown) and the fence's revision.
Other features call `check_point` / `check_route` (rules.OutsideGeofence, answered 422) before they
store or publish a waypoint or send a mission. The /fix callback (waypoints) hands positions to
`note_position`; the geofence loop checks them, raises the event on every crossing and, with
ROVER_WEB_GEOFENCE_ESTOP, engages the e-stop when the robot leaves.
"""

from __future__ import annotations

import json

from rover_web.config import ROOT, ConfigError
from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.estop import EStopService
from rover_web.panels.oplog import OperatorLog

from . import routes
from .routes import outside_geofence_response
from .rules import OutsideGeofence, parse_fence
from .service import CHANNEL, GeofenceService
from .store import GeofenceStore

__all__ = ["init_app", "GeofenceService", "OutsideGeofence", "outside_geofence_response"]

CHECK_PERIOD_S = 0.1


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)
    app.context_processor(lambda: {"geofence_state": current_feature(GeofenceService).state()})


def _init_robot(rover: Rover) -> None:
    config = rover.config
    service = GeofenceService(GeofenceStore(rover.db), rover.feature(EStopService), rover.hub,
                              max_vertices=config["ROVER_WEB_GEOFENCE_MAX_VERTICES"],
                              engage_estop=config["ROVER_WEB_GEOFENCE_ESTOP"],
                              oplog=OperatorLog(rover.db, config["ROVER_WEB_PANELS_LOG_KEEP"],
                                                          audit=rover.audit))
    rover.hub.register(CHANNEL)
    if config["ROVER_WEB_GEOFENCE_FILE"]:
        service.seed(_read_file(config["ROVER_WEB_GEOFENCE_FILE"], service.max_vertices))
    rover.add_feature(service)
    rover.hub.publish(CHANNEL, service.state())
    rover.every(CHECK_PERIOD_S, service.evaluate, name="geofence-check", only_while=service.pending)


def _read_file(name: str, max_vertices: int) -> dict:
    path = ROOT / name
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
        parse_fence(doc, max_vertices)
    except (OSError, ValueError) as exc:  # InvalidInput is a ValueError too
        raise ConfigError(f"ROVER_WEB_GEOFENCE_FILE: {path}: {exc}") from None
    return doc
