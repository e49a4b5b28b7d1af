"""LiveMap overlays: what the robot senses, drawn on the map page.

ROS: subscribes a sensor_msgs/LaserScan (ROVER_WEB_SCAN_TOPIC), nav_msgs/OccupancyGrid costmaps
(ROVER_WEB_COSTMAP_TOPICS), a visualization_msgs/MarkerArray (ROVER_WEB_MARKERS_TOPIC), a
geometry_msgs/PolygonStamped footprint (ROVER_WEB_FOOTPRINT_TOPIC), each placed in the map through
TF (rover_web/placement.py), and the AMCL pose (else TF's map -> base_link: the recent path, and the
fallback's robot when TF does not know a message's frame).
SSE: `scan` (and `scan3d`, the 3D view's, with heights), `costmap`, `markers`, `footprint`, each
rate-limited. HTTP: GET /api/overlays.
Modules: service (the per-app object), scan (thinning), costmap (encoding), markers (the set),
poses (pose history), counts, msgs, routes.
"""

from __future__ import annotations

from rover_web.config import TOPIC_KEYS
from rover_web.core import robots
from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover

from . import bounds, msgs, routes
from .bounds import bounded
from .service import CHANNELS, COSTMAP_CHECK_S, TF_POSE_S, OverlayService

MARKER_EXPIRY_S = 0.5


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)


def reader_topics(settings) -> list[str]:
    """Every overlay topic of every robot, as _init_robot will subscribe them: read before the ROS
    node exists, so that their DDS readers get a profile of their own (ros/dds_profiles.py)."""
    names: list[str] = []
    for robot in robots.parse(settings["ROVER_WEB_ROBOTS"]):
        config = robots.settings_for(robot, settings, TOPIC_KEYS)
        names += [config["ROVER_WEB_SCAN_TOPIC"], config["ROVER_WEB_MARKERS_TOPIC"],
                  config["ROVER_WEB_FOOTPRINT_TOPIC"], *config["ROVER_WEB_COSTMAP_TOPICS"]]
    return [name for name in names if name]


def _init_robot(rover: Rover) -> None:
    service = OverlayService(rover)
    rover.add_feature(service)
    rover.hub.register(*CHANNELS)
    runtime = rover.runtime
    config = rover.config
    runtime.subscribe(msgs.AMCL_POSE, config["ROVER_WEB_AMCL_POSE_TOPIC"],
                      lambda m: service.on_pose(*msgs.amcl_pose(m)), "latched", track=False)
    # The overlay topics are taken raw and their length checked before rclpy deserializes them;
    # scans and markers only while a page watches (bounds.py, issue 40).
    watching = rover.hub.watchers
    if service.scan_topic:
        runtime.subscribe(msgs.LASER_SCAN, service.scan_topic, bounded(
            service.counts["scan"], bounds.SCAN_MAX_BYTES, msgs.deserializer(msgs.LASER_SCAN),
            lambda m: service.on_scan(msgs.scan(m)), lambda: watching("scan") + watching("scan3d") > 0), "sensor_data",
            raw=True)
    for topic in service.costmap_topics:
        # Nav2 publishes its costmaps transient local: a page opened later still gets the global one.
        runtime.subscribe(msgs.OCCUPANCY_GRID, topic, bounded(
            service.counts["costmap"], bounds.grid_max_bytes(service.costmap_max_cells),
            msgs.deserializer(msgs.OCCUPANCY_GRID), lambda m, t=topic: service.on_costmap(t, msgs.grid(m))),
            "latched", raw=True)
    if service.markers_topic:
        # One reader shared with the 3D view (bounds.MARKERS_SHARED): each reader of its own reassembles
        # a hostile array whole, so two cost twice its size before either could refuse it.
        runtime.subscribe(msgs.MARKER_ARRAY, service.markers_topic, bounded(
            service.counts["markers"], bounds.MARKERS_MAX_BYTES, msgs.deserializer(msgs.MARKER_ARRAY),
            lambda m: service.on_markers(msgs.markers(m), len(m.markers) - bounds.MARKERS_MAX_COUNT),
            lambda: watching("markers") > 0), bounds.MARKERS_DEPTH, **bounds.MARKERS_SHARED)
    if service.footprint_topic:
        runtime.subscribe(msgs.POLYGON_STAMPED, service.footprint_topic, bounded(
            service.counts["footprint"], bounds.FOOTPRINT_MAX_BYTES, msgs.deserializer(msgs.POLYGON_STAMPED),
            lambda m: service.on_footprint(*msgs.polygon(m))), 1, raw=True)
    if service.costmap_topics or service.footprint_topic:
        # Nav2's local costmap and footprint are in `odom`: placed with AMCL's map -> odom (frames.py),
        # from the /odom subscription telemetry already has (one, shared, raw).
        runtime.subscribe(msgs.ODOMETRY, config["ROVER_WEB_ODOM_TOPIC"], service.on_odom, qos=10, raw=True,
                          share=True, track=not runtime.tracks(config["ROVER_WEB_ODOM_TOPIC"]))
    if service.costmap_topics:
        rover.every(COSTMAP_CHECK_S, service.encode_costmaps, name="overlays-costmap")
    if service.placer.buffer is not None:
        rover.every(TF_POSE_S, service.pose_from_tf, name="overlays-tf-pose")
    if service.markers_topic:
        rover.every(MARKER_EXPIRY_S, service.expire_markers, name="overlays-marker-expiry")
