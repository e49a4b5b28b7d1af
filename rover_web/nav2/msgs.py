"""Nav2's messages: goals built, feedback and results read into plain values, lifecycle states.

The only module of rover_web that imports nav2_msgs, and only when asked (`missing()` first):
nav2_msgs has no wheel on PyPI, and rover_web runs without it. lifecycle_msgs comes with
ros-common-interfaces and is always there.
"""

from __future__ import annotations

import importlib
import importlib.util

from rover_web.ros.convert import quaternion_from_yaw, stamp_to_float, yaw_from_quaternion
from rover_web.web.api_messages import Text, said

# kind -> (action name under the robot's namespace, nav2_msgs/action type)
ACTIONS = {"to_pose": ("navigate_to_pose", "NavigateToPose"),
           "through_poses": ("navigate_through_poses", "NavigateThroughPoses"),
           "follow_waypoints": ("follow_waypoints", "FollowWaypoints")}
HOW_TO_GET = said("nav2_msgs has no wheel on PyPI: on a robot, source ROS 2 Jazzy with Nav2 "
                  "(/opt/ros/jazzy/setup.bash, package ros-jazzy-nav2-msgs) before starting rover_web; "
                  "elsewhere build it into this Python environment with scripts/build_interfaces.sh")
# Nav2 Jazzy's error codes of the servers bt_navigator hands on in its results (their ranges do not
# overlap); a code nav2_msgs itself names is looked up there first.
ERROR_NAMES = {
    # FollowPath (controller_server)
    100: "UNKNOWN", 101: "INVALID_CONTROLLER", 102: "TF_ERROR", 103: "INVALID_PATH", 104: "PATIENCE_EXCEEDED",
    105: "FAILED_TO_MAKE_PROGRESS", 106: "NO_VALID_CONTROL",
    # ComputePathToPose / ComputePathThroughPoses (planner_server)
    200: "UNKNOWN", 201: "INVALID_PLANNER", 202: "TF_ERROR", 203: "START_OUTSIDE_MAP", 204: "GOAL_OUTSIDE_MAP",
    205: "START_OCCUPIED", 206: "GOAL_OCCUPIED", 207: "TIMEOUT", 208: "NO_VALID_PATH", 209: "NO_VIAPOINTS_GIVEN",
    # SmoothPath (smoother_server)
    500: "UNKNOWN", 501: "INVALID_SMOOTHER", 502: "TIMEOUT", 503: "SMOOTHED_PATH_IN_COLLISION",
    504: "FAILED_TO_SMOOTH_PATH", 505: "INVALID_PATH",
    # FollowWaypoints (waypoint_follower)
    600: "UNKNOWN", 601: "TASK_EXECUTOR_FAILED",
    # behaviors (Spin, BackUp, DriveOnHeading, ...)
    701: "TIMEOUT", 702: "TF_ERROR", 703: "COLLISION_AHEAD",
}
LIFECYCLE_STATES = {0: "unknown", 1: "unconfigured", 2: "inactive", 3: "active", 4: "finalized",
                    10: "configuring", 11: "cleaningup", 12: "shuttingdown", 13: "activating",
                    14: "deactivating", 15: "errorprocessing"}

_error_names: dict[int, str] | None = None


def missing(load: bool = False) -> Text | None:
    """Why Nav2's actions cannot be used here (what is missing and how to get it), or None.

    At start only found, not loaded (`load=False`): a robot nobody navigates from the GUI does not
    pay for nav2_msgs' classes (issue 32: idle RSS). The first real use loads it (`load=True`)."""
    try:
        if load:
            importlib.import_module("nav2_msgs.action")
        elif importlib.util.find_spec("nav2_msgs.action") is None:
            return said("nav2_msgs is not installed. %(how)s", how=HOW_TO_GET)
    except ImportError as exc:
        return said("nav2_msgs could not be imported (%(why)s). %(how)s", why=str(exc), how=HOW_TO_GET)
    return None


def action_type(kind: str) -> type:
    module = importlib.import_module("nav2_msgs.action")
    return getattr(module, ACTIONS[kind][1])


def _pose_stamped(x: float, y: float, yaw: float, frame_id: str, stamp):
    from geometry_msgs.msg import PoseStamped

    pose = PoseStamped()
    pose.header.stamp = stamp
    pose.header.frame_id = frame_id
    pose.pose.position.x, pose.pose.position.y = float(x), float(y)
    o = pose.pose.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
    return pose


def goal(kind: str, poses: list[tuple[float, float, float]], frame_id: str, stamp):
    """A fresh goal message: NavigateToPose for one pose, the other two for a route."""
    msg = action_type(kind).Goal()
    stamped = [_pose_stamped(x, y, yaw, frame_id, stamp) for x, y, yaw in poses]
    if kind == "to_pose":
        msg.pose = stamped[0]
    else:
        msg.poses = stamped
    return msg


def _seconds(duration) -> float:
    return duration.sec + duration.nanosec * 1e-9


def _pose_values(stamped) -> dict:
    p, q = stamped.pose.position, stamped.pose.orientation
    return {"x": p.x, "y": p.y, "yaw": yaw_from_quaternion(q.x, q.y, q.z, q.w), "frame_id": stamped.header.frame_id,
            "stamp": stamp_to_float(stamped.header.stamp)}


def feedback(kind: str, msg) -> dict:
    """The feedback as the panel shows it (seconds and metres, rounded)."""
    if kind == "follow_waypoints":
        return {"current_waypoint": int(msg.current_waypoint)}
    out = {"current_pose": {k: (round(v, 4) if isinstance(v, float) else v)
                            for k, v in _pose_values(msg.current_pose).items()},
           "navigation_time_s": round(_seconds(msg.navigation_time), 3),
           "estimated_time_remaining_s": round(_seconds(msg.estimated_time_remaining), 3),
           "number_of_recoveries": int(msg.number_of_recoveries),
           "distance_remaining_m": round(float(msg.distance_remaining), 3)}
    if kind == "through_poses":
        out["number_of_poses_remaining"] = int(msg.number_of_poses_remaining)
    return out


def error_name(code: int) -> str | None:
    """Nav2's name for an error code: the result constants of every nav2_msgs action (their ranges do not
    overlap: 200s ComputePathToPose, 100s FollowPath, 600s FollowWaypoints, 9000s the navigators...)."""
    global _error_names
    if code == 0:
        return "NONE"
    if _error_names is None:
        names: dict[int, str] = dict(ERROR_NAMES)
        module = importlib.import_module("nav2_msgs.action")
        for attr in dir(module):
            result = getattr(getattr(module, attr), "Result", None)
            for name in dir(result) if result is not None else ():
                value = getattr(result, name, None)
                if name.isupper() and isinstance(value, int) and not isinstance(value, bool) and value:
                    names[value] = name
        _error_names = names
    return _error_names.get(code)


def result(kind: str, msg) -> dict:
    code = int(getattr(msg, "error_code", 0))
    out = {"error_code": code, "error_name": error_name(code), "error_msg": str(getattr(msg, "error_msg", ""))}
    if kind == "follow_waypoints":
        # Jazzy: nav2_msgs/MissedWaypoint {index, goal, error_code}
        out["missed_waypoints"] = [
            {"index": int(s.index), "error_code": int(s.error_code), "error_name": error_name(int(s.error_code)),
             "pose": _pose_values(s.goal)}
            for s in msg.missed_waypoints]
    return out


# --- lifecycle ---

def get_state_type() -> type:
    from lifecycle_msgs.srv import GetState

    return GetState


def lifecycle_state(response) -> str:
    state = response.current_state
    return LIFECYCLE_STATES.get(int(state.id), state.label or "unknown")
