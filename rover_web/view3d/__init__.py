"""The 3D view (docs/view3d.md): the robot's URDF model moved by TF, its markers and point cloud.

ROS: subscribes the robot description (std_msgs/String, transient local; ROVER_WEB_ROBOT_DESCRIPTION_TOPIC)
unless ROVER_WEB_URDF_FILE names a file, a sensor_msgs/PointCloud2 (ROVER_WEB_POINTCLOUD_TOPIC), and the
overlays' MarkerArray (ROVER_WEB_MARKERS_TOPIC, one subscription shared with them). TF comes from the tf
feature's buffer (rover_web/tf), which must be set up before this one.
SSE: `view3d` (every TF frame's pose in the base frame, ROVER_WEB_VIEW3D_POSE_HZ), `view3d_robot` (the
description changed), `view3d_markers`. HTTP: /3d, /api/3d/robot, /api/3d/mesh/..., /api/3d/cloud.
Modules: service, urdf_model (parse, errors with their line), meshes (package:// inside share folders),
cloud (voxel thinning, the binary frame), poses, markers, msgs, routes.
"""

from __future__ import annotations

import logging

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.i18n import N_
from rover_web.overlays.bounds import MARKERS_MAX_BYTES, bounded
from rover_web.tf import TfService

from . import msgs, routes
from .cloud import MAX_SOURCE_POINTS
from .service import CHANNELS, View3dService
from .urdf_model import MAX_URDF_BYTES

log = logging.getLogger(__name__)
MARKER_EXPIRY_S = 0.5
DESCRIPTION_MAX_BYTES = MAX_URDF_BYTES + 1024  # the URDF text and the CDR around it
CLOUD_MAX_BYTES = MAX_SOURCE_POINTS * 32 + 64 * 1024  # 32-byte points (x, y, z, intensity, ring, time...)


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)


def _init_robot(rover: Rover) -> None:
    service = View3dService(rover)
    rover.add_feature(service)
    rover.hub.register(*CHANNELS)
    rover.add_nav(N_("3D"), "/3d")
    tf = rover.feature(TfService)  # set up before this feature (create_app)
    service.tf, service.tf_missing = tf.buffer, tf.missing
    runtime = rover.runtime
    hub = rover.hub
    # Taken raw and bounded before rclpy deserializes anything (overlays/bounds.py, issue 40); markers
    # and clouds only while a page shows them. The description is kept regardless: it is latched.
    if service.urdf_file:
        service.load_file()
    elif service.description_topic:
        runtime.subscribe(msgs.STRING, service.description_topic, bounded(
            service.description_counts, DESCRIPTION_MAX_BYTES, msgs.deserializer(msgs.STRING),
            lambda m: service.on_description(msgs.description(m), service.description_topic)), "latched", raw=True)
    if service.cloud_topic:
        runtime.subscribe(msgs.POINT_CLOUD2, service.cloud_topic, bounded(
            service.cloud_bound, CLOUD_MAX_BYTES, msgs.deserializer(msgs.POINT_CLOUD2),
            lambda m: service.on_cloud(lambda: msgs.point_cloud(m)), service.cloud_watched), "sensor_data", raw=True)
    if service.markers_topic:
        # A subscription of its own beside the overlays' (theirs keeps x, y and yaw only), deserialized
        # only while a 3D view is open.
        runtime.subscribe(msgs.MARKER_ARRAY, service.markers_topic, bounded(
            service.markers_bound, MARKERS_MAX_BYTES, msgs.deserializer(msgs.MARKER_ARRAY),
            lambda m: service.on_markers(msgs.markers(m)), lambda: hub.watchers("view3d_markers") > 0),
            10, raw=True, track=not runtime.tracks(service.markers_topic))
        rover.every(MARKER_EXPIRY_S, service.expire_markers, name="view3d-marker-expiry")
    rover.every(1.0 / service.pose_hz, service.tick, name="view3d-poses")
