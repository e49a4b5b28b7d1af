"""Nav2's navigation actions from the GUI: goals and routes, their feedback, cancel, results, and Nav2's servers.

  GET  /api/nav2         the goal shown (one at a time, as bt_navigator runs one), its last feedback,
                         its result, the action servers reachable and Nav2's lifecycle states
  POST /api/nav2/goal    NavigateToPose to {map, x, y, yaw}: on the map, outside its keep-out areas (422)
  POST /api/nav2/route   {map, mode: through_poses | follow_waypoints, poses: [...]}: every pose checked
  POST /api/nav2/cancel  cancel the goal shown
  SSE  nav2              that state, at most ROVER_WEB_NAV2_FEEDBACK_MAX_HZ
  ROS  action clients of navigate_to_pose, navigate_through_poses, follow_waypoints and GetState clients of
       `<node>/get_state` for ROVER_WEB_NAV2_LIFECYCLE_NODES, on the robot's own side node (ros/goal_client.py)

Without nav2_msgs (no wheel on PyPI) everything but the POSTs works: they answer 503 with what is
missing and how to get it, and LiveMap sends goals on ROVER_WEB_GOAL_TOPIC. The e-stop and the end
of the sender's credentials cancel the goal; shutdown does too. Modules: service, routes, msgs.
"""

from __future__ import annotations

from rover_web.core.fleet import Fleet
from rover_web.core.state import Rover
from rover_web.estop import EStopService

from . import routes
from .service import CHANNEL, Nav2Service

__all__ = ["init_app", "Nav2Service"]


def init_app(app, fleet: Fleet) -> None:
    for rover in fleet:
        _init_robot(rover)
    app.register_blueprint(routes.bp)


def _init_robot(rover: Rover) -> None:
    service = Nav2Service(rover, rover.feature(EStopService))
    rover.add_feature(service)
    rover.hub.register(CHANNEL)
    rover.hub.publish(CHANNEL, service.state())
    rover.every(rover.config["ROVER_WEB_NAV2_LIFECYCLE_PERIOD_S"], service.poll_lifecycle, name="nav2-lifecycle",
                immediately=True, only_while=service.watching)
    rover.on_shutdown(service.close)
