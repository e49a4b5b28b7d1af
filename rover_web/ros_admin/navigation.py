"""Navigation goals /ros refuses: they would move the robot without the keep-out and geofence checks.

The routes made for moving the robot somewhere check first: a LiveMap goal against the map's
keep-out areas (POST /api/maps/<map>/goal), a waypoint mission against the GPS geofence
(POST /api/waypoints/send). An action goal from /ros is any type with any fields, so rather than
guess where a position hides in it (and in which frame), goals of the known navigation actions
are refused, recognised by type (nav2's, checked by name, before anything is imported) or by the
action's own name. Pure Python.
"""

from __future__ import annotations

from rover_web.web.api_messages import explain

# nav2_msgs actions that move the robot (ComputePathToPose, ComputePathThroughPoses and SmoothPath
# only plan, and stay allowed).
NAV2_MOTION = frozenset({"NavigateToPose", "NavigateThroughPoses", "FollowWaypoints", "FollowGPSWaypoints",
                         "FollowPath", "Spin", "BackUp", "DriveOnHeading", "AssistedTeleop", "DockRobot",
                         "UndockRobot"})
# The names nav2 (and its GPS and docking servers) serve those actions under, in any namespace.
MOTION_ACTION_NAMES = frozenset({"navigate_to_pose", "navigate_through_poses", "follow_waypoints",
                                 "follow_gps_waypoints", "follow_path", "spin", "backup", "drive_on_heading",
                                 "assisted_teleop", "dock_robot", "undock_robot", "move_base"})
ROUTES = ("send a goal on the LiveMap (POST /api/maps/<map>/goal), which checks the map's keep-out areas, "
          "or a waypoint mission (POST /api/waypoints/send), which checks the geofence")


def navigation_refusal(action: str, type_name: object) -> str | None:
    """Why a goal to `action` of `type_name` is refused, or None."""
    package, _, name = type_name.partition("/action/") if isinstance(type_name, str) else ("", "", "")
    if package == "nav2_msgs" and name in NAV2_MOTION:
        return explain("%(type)s goals move the robot unchecked from here: %(routes)s", type=type_name, routes=ROUTES)
    if action.rstrip("/").rpartition("/")[2] in MOTION_ACTION_NAMES:
        return explain("%(action)s is a navigation action; its goals move the robot unchecked from here: %(routes)s",
                       action=action, routes=ROUTES)
    return None
