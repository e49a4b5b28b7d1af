"""The odom frame placed in the map frame without TF: AMCL's map -> odom transform, rebuilt from the
two poses rover_web already hears. Pure.

Nav2's local costmap and its published footprint are in `odom` by default (its global_frame), not
in `map`. AMCL's own map -> odom transform is map_T_base · (odom_T_base)⁻¹ at the moment of its
pose estimate: the robot's map pose (/amcl_pose) composed with the inverse of its odometry pose
(/odom) at the same stamp. It holds until AMCL's next estimate, as AMCL's TF does, so a grid in
`odom` is drawn where AMCL would put it. The odom frame's name is the one /odom's header carries.
"""

from __future__ import annotations

import math
import threading

from .poses import PoseHistory

Pose2D = tuple[float, float, float]


def compose(a: Pose2D, b: Pose2D) -> Pose2D:
    """a ∘ b: the pose b, given in a's frame, in the frame a is given in."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], math.atan2(math.sin(a[2] + b[2]),
                                                                                math.cos(a[2] + b[2])))


def invert(a: Pose2D) -> Pose2D:
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-c * a[0] - s * a[1], s * a[0] - c * a[1], -a[2])


class OdomInMap:
    def __init__(self, keep_s: float = 10.0):
        self._odom = PoseHistory(keep_s=keep_s)
        self._lock = threading.Lock()
        self.frame_id: str | None = None  # what /odom's header names its frame
        self._map_pose: tuple[float, Pose2D] | None = None  # AMCL's latest: (stamp, pose)

    def on_odom(self, frame_id: str, stamp: float, pose: Pose2D) -> None:
        if all(map(math.isfinite, (stamp, *pose))):
            self.frame_id = frame_id.lstrip("/") or None
            self._odom.add(stamp, *pose)

    def on_map_pose(self, stamp: float, pose: Pose2D) -> None:
        with self._lock:
            self._map_pose = (stamp, pose)

    def transform(self, frame_id: str) -> Pose2D | None:
        """map_T_odom when `frame_id` is the odom frame and AMCL and odometry have both been heard.

        Worked out when asked (a grid or a footprint, a few a second), not per pose: AMCL's latched
        pose often arrives before the first odometry."""
        if self.frame_id is None or frame_id.lstrip("/") != self.frame_id:
            return None
        with self._lock:
            map_pose = self._map_pose
        if map_pose is None:
            return None
        odom = self._odom.at(map_pose[0])
        return None if odom is None else compose(map_pose[1], invert(odom))
