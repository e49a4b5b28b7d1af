"""GPS waypoints: the RobotX GUI's map click, a persistent mission editor, and the robot's live fix.

HTTP (routes.py; the rules live in store, geojson and gps):
  POST /waypoints                      the seeds' call: append, publish [lng, lat] on /waypoints
  GET  /waypoints                      server-rendered table of the mission (no JavaScript needed)
  GET/POST/DELETE /api/waypoints       list, add (optional label), clear
  PATCH/DELETE /api/waypoints/<id>     move (lng/lat), rename (label), reorder (index), delete
  POST /api/waypoints/send             the whole ordered mission on /mission (n x 2 Float64MultiArray)
  GET/POST /api/waypoints/geojson      export / import (replace) as a GeoJSON FeatureCollection
SSE: `waypoints` (the stored mission, at most 10 Hz, broadcaster.py), `fix` (robot position, fix
quality, accuracy and track, 5 Hz, from NavSatFix on ROVER_WEB_FIX_TOPIC) and `heading` (compass
bearing, 10 Hz, from ROVER_WEB_GPS_HEADING_TOPIC; heading.py). Through TF (mounts.py) the fix is moved
from the antenna to base_link and an IMU's heading turned by its mount; each says `placed_by`.

Every waypoint added, by either POST, is stored (committed, fsynced) first and then published on
/waypoints, so an acknowledged waypoint is both on disk and on the wire. Moves, reorders, deletes
and imports change only the stored mission; the robot gets them with "send mission".
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover, current_feature
from rover_web.estop import EStopService
from rover_web.geofence import GeofenceService
from rover_web.i18n import N_

from . import broadcaster, routes
from .msgs import HEADING_TYPES, NAV_SAT_FIX, fix_reading, heading_orientation, odometry_yaw
from .service import FIX_CHANNEL, HEADING_CHANNEL, WaypointsService


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)
    app.context_processor(lambda: {"waypoints_panel": current_feature(WaypointsService).panel_context})


def _init_robot(rover: Rover) -> None:
    service = WaypointsService(rover, rover.feature(EStopService), rover.feature(GeofenceService))
    rover.add_feature(service)
    rover.hub.register(broadcaster.CHANNEL, FIX_CHANNEL, HEADING_CHANNEL)
    config = rover.config
    rover.runtime.subscribe(NAV_SAT_FIX, config["ROVER_WEB_FIX_TOPIC"],
                            lambda msg: service.on_fix(fix_reading(msg)), qos="sensor_data")
    heading_topic, kind = config["ROVER_WEB_GPS_HEADING_TOPIC"], config["ROVER_WEB_GPS_HEADING_TYPE"]
    if heading_topic:
        if kind == "odometry":
            # Usually /odom, which telemetry reads too: one raw subscription between them (the same
            # QoS as telemetry's), each message taken once and read at known offsets (ros/cdr.py).
            rover.runtime.subscribe(HEADING_TYPES[kind], heading_topic,
                                    lambda raw: service.on_heading(odometry_yaw(raw)), qos=10, raw=True, share=True,
                                    track=not rover.runtime.tracks(heading_topic))
        else:
            rover.runtime.subscribe(HEADING_TYPES[kind], heading_topic,
                                    lambda msg: service.on_orientation(*heading_orientation(msg, kind)),
                                    qos="sensor_data",
                                    track=not rover.runtime.tracks(heading_topic))
        rover.every(min(0.5, config["ROVER_WEB_GPS_HEADING_STALE_S"] / 2), service.check_heading,
                    name="gps-heading-staleness")
    service.broadcaster.start()
    rover.on_shutdown(service.broadcaster.stop)
    rover.on_shutdown(service.store.close)  # runs first: queued changes commit before the db closes
    rover.add_panel(20, "panels/waypoints.html", N_("GPS waypoints"),
                    channels=(broadcaster.CHANNEL, FIX_CHANNEL, HEADING_CHANNEL))
    rover.add_nav(N_("Waypoints"), "/waypoints")
