"""LiveMap: floorplans from map_files, the live robot pose, its goal and plan, click-to-goal.

ROS: subscribes /amcl_pose (transient local; without it the pose is TF's map -> base_link, looked
up on a tick: service.py), /goal_pose, /plan (placed through TF when in another frame) and optionally an OccupancyGrid
(/map, transient local) drawn into a map named "live map"; publishes goals on /goal_pose and the
operator's initial pose on /initialpose.
SSE: `pose` (at most LIVEMAP_POSE_MAX_HZ), `goal`, `plan` (at most 5 Hz), `live_map` (new grid).
HTTP: /livemap pages and /api/maps... (see routes.py and README.md).
Modules: service (the per-app object), routes, state (LiveMap and the robot's track), map_files,
geometry, occupancy, initial_pose (its input), msgs.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.i18n import N_

from . import msgs, routes
from .service import STALE_CHECK_S, LiveMapService, load_files


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)  # with the dashboard card's context (livemap_panel)


def _init_robot(rover: Rover) -> None:
    config = rover.config
    files = load_files(config)
    runtime = rover.runtime
    goal_publisher = runtime.publisher(msgs.POSE_STAMPED, config["ROVER_WEB_GOAL_TOPIC"], "default")
    initial_pose_publisher = runtime.publisher(msgs.AMCL_POSE, config["ROVER_WEB_INITIAL_POSE_TOPIC"], "default")
    service = LiveMapService(rover, files, goal_publisher, rover.feature(EStopService), initial_pose_publisher)
    rover.add_feature(service)

    rover.hub.register("pose", "goal", "plan", "live_map")
    runtime.subscribe(msgs.AMCL_POSE, config["ROVER_WEB_AMCL_POSE_TOPIC"],
                      lambda m: service.on_pose(msgs.pose_from_amcl(m)), "latched")
    runtime.subscribe(msgs.POSE_STAMPED, service.goal_topic, lambda m: service.on_goal(msgs.pose_from_stamped(m)),
                      "default")
    runtime.subscribe(msgs.PATH, config["ROVER_WEB_PLAN_TOPIC"], lambda m: service.on_plan(*msgs.path_points(m)), 1)
    if service.map_topic:
        runtime.subscribe(msgs.OCCUPANCY_GRID, service.map_topic, lambda m: service.on_grid(*msgs.occupancy_grid(m)),
                          "latched")

    rover.add_panel(30, "panels/livemap.html", N_("Live map"), channels=("pose",))
    rover.add_nav(N_("Live map"), "/livemap")
    rover.every(STALE_CHECK_S, service.check_staleness, name="livemap-staleness")
    if service.placer.buffer is not None:
        rover.every(service.tf_pose_period_s, service.pose_from_tf, name="livemap-tf-pose")
