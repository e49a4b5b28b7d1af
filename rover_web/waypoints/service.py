"""The waypoints feature's per-app object: the stored mission, its two topics and the robot's fix."""

from __future__ import annotations

import dataclasses
import logging
import math

from rover_web.basemap.source import map_view
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.geofence import GeofenceService, OutsideGeofence
from rover_web.placement import tf_buffer
from rover_web.web.api_messages import explain

from .broadcaster import MissionBroadcaster
from .gps import FixReading, GpsTrack
from .heading import Heading, yaw_of_quaternion
from .mounts import base_yaw, robot_centre
from .msgs import FLOAT64_MULTI_ARRAY, mission_message, waypoint_message
from .store import EmptyMission, Mission, StaleRevision, Waypoint, WaypointStore

FIX_CHANNEL = "fix"
FIX_CHANNEL_MAX_HZ = 5.0
HEADING_CHANNEL = "heading"
HEADING_CHANNEL_MAX_HZ = 10.0
# Every waypoint is a command the robot must not miss: keep enough history that a subscriber a
# few hundred milliseconds behind a burst of clicks (or a script) still receives all of them.
log = logging.getLogger(__name__)

WAYPOINT_QOS_DEPTH = 1000


class WaypointsService:
    def __init__(self, rover: Rover, estop: EStopService, geofence: GeofenceService):
        config = rover.config
        self.config = config
        self.estop = estop
        self.geofence = geofence
        self.store = WaypointStore(rover.db, config["ROVER_WEB_MAX_WAYPOINTS"])
        runtime = rover.runtime
        self.waypoint_topic = config["ROVER_WEB_WAYPOINTS_TOPIC"]
        self.mission_topic = config["ROVER_WEB_MISSION_TOPIC"]
        self.waypoint_pub = runtime.publisher(FLOAT64_MULTI_ARRAY, self.waypoint_topic, qos=WAYPOINT_QOS_DEPTH)
        self.mission_pub = runtime.publisher(FLOAT64_MULTI_ARRAY, self.mission_topic, qos=10)
        self.hub = rover.hub
        self.track = GpsTrack(config["ROVER_WEB_FIX_TRACK_POINTS"])
        self.heading = Heading(config["ROVER_WEB_GPS_HEADING_TOPIC"], config["ROVER_WEB_GPS_HEADING_OFFSET_DEG"],
                               config["ROVER_WEB_GPS_HEADING_STALE_S"])
        self.broadcaster = MissionBroadcaster(self.store, rover.hub)
        self.tf = tf_buffer(rover)
        self.base_frame = config.get("ROVER_WEB_BASE_FRAME", "base_link")

    def _mount(self, frame: str):
        """TF's sensor <- base_link... as base_link <- frame's transform, or None (no TF, unknown, the base itself)."""
        frame = frame.lstrip("/")
        if self.tf is None or not frame or frame == self.base_frame:
            return None
        from rover_web.tf.buffer import TfError

        try:
            return self.tf.lookup(self.base_frame, frame, None)
        except TfError:
            return None

    def on_fix(self, reading: FixReading) -> None:
        placed_by, offset = "antenna", None
        mount = self._mount(reading.frame_id)
        heading = self.heading.state()
        if mount is not None and heading is not None and not heading["stale"] \
                and math.isfinite(reading.lat) and math.isfinite(reading.lng):
            offset = (mount.translation[0], mount.translation[1])
            yaw_enu = heading["yaw_rad"] + math.radians(self.heading.offset_deg)
            lat, lng = robot_centre(reading.lat, reading.lng, offset, yaw_enu)
            reading, placed_by = dataclasses.replace(reading, lat=lat, lng=lng), "tf"
        state = {**self.track.update(reading), "placed_by": placed_by,
                 "antenna_offset_m": None if offset is None else [round(v, 3) for v in offset]}
        self.hub.publish_throttled(FIX_CHANNEL, state, FIX_CHANNEL_MAX_HZ)
        if state["fix"]:
            self.geofence.note_position(state["lng"], state["lat"])

    def on_heading(self, yaw_rad: float | None, placed_by: str = "message") -> None:
        state = self.heading.update(yaw_rad)
        if state is not None:
            self.hub.publish_throttled(HEADING_CHANNEL, {**state, "placed_by": placed_by}, HEADING_CHANNEL_MAX_HZ)

    def on_orientation(self, orientation, frame: str) -> None:
        """A heading sensor's orientation: its mount on the robot (TF's frame <- base_link) composed in."""
        if orientation is None:
            self.on_heading(None)
            return
        mount = self._mount(frame)
        if mount is None:
            self.on_heading(yaw_of_quaternion(*orientation))
            return
        if yaw_of_quaternion(*orientation) is None:
            self.on_heading(None)
            return
        norm = math.sqrt(sum(v * v for v in orientation))
        q = tuple(v / norm for v in orientation)
        self.on_heading(base_yaw(q, mount.inverse().rotation), "tf")

    def check_heading(self) -> None:
        stale = self.heading.went_stale()
        if stale is not None:
            self.hub.publish(HEADING_CHANNEL, stale)

    # --- changes ---

    def add(self, lng: float, lat: float, label: str = "") -> Waypoint:
        self.estop.check_motion()  # every add is published on /waypoints: a command to the robot
        self.geofence.check_point(lng, lat)  # refused before it is stored or published
        # Published once committed, by the committer thread: /waypoints carries the waypoints in
        # the mission's order even when several browsers or scripts add at the same moment.
        waypoint, _revision = self.store.add(lng, lat, label, announce=self._announce)
        self.broadcaster.changed()
        return waypoint

    def _announce(self, waypoint: Waypoint) -> None:
        if self.estop.engaged:  # engaged between the check and the commit: kept, not sent
            log.warning("waypoint %d stored but not published: the e-stop engaged meanwhile", waypoint.id)
            return
        self.waypoint_pub.publish(waypoint_message(waypoint.lng, waypoint.lat))

    def move(self, waypoint_id: int, **changes) -> tuple[Waypoint, int]:
        """Update one waypoint; a move outside the geofence is refused inside the transaction."""
        result = self.store.update(waypoint_id, check=self.geofence.check_point, **changes)
        self.broadcaster.changed()
        return result

    def replace(self, points) -> Mission:
        """The GeoJSON import: every point must lie inside the geofence, or nothing changes."""
        for i, (lng, lat, _label) in enumerate(points):
            refused = self.geofence.fence.refusal(lng, lat)
            if refused is not None:
                raise OutsideGeofence(
                    explain("features[%(i)s]: %(refused)s", i=i, refused=refused), **refused.details, waypoint=i
                )
        mission = self.store.replace(points)
        self.broadcaster.changed()
        return mission

    def changed(self) -> None:
        self.broadcaster.changed()

    def send_mission(self, expected_revision: int | None) -> dict:
        mission = self.store.mission()
        if expected_revision is not None and expected_revision != mission.revision:
            raise StaleRevision(mission.revision)
        if not mission.waypoints:
            raise EmptyMission()
        self.estop.check_motion()
        self.geofence.check_route([(w.lng, w.lat) for w in mission.waypoints])
        self.mission_pub.publish(mission_message([(w.lng, w.lat) for w in mission.waypoints]))
        return {"sent": len(mission.waypoints), "topic": self.mission_topic, **mission.to_dict()}

    # --- views' data ---

    def map_config(self) -> dict:
        return {**map_view(self.config), "max_waypoints": self.store.max_waypoints}

    def panel_context(self) -> dict:
        return {"mission": self.store.mission(), "map": self.map_config(), "fix": self.track.state(),
                "heading": self.heading.state(),
                "geofence": self.geofence.collection()}
