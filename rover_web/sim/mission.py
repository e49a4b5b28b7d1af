"""The simulated robot drives the GPS mission the waypoint editor sends, one waypoint after another.

"Send mission" publishes std_msgs/Float64MultiArray on `mission`: [lng0, lat0, lng1, lat1, ...]
(docs/waypoints.md). Each waypoint is laid on the robot's map frame by the same local tangent
plane its GPS fix comes from, so the fix arrives exactly at the clicked point. Each waypoint in
turn becomes the goal of the robot's goal follower, facing the next leg so it drives straight on.

Progress goes where the GUI already looks: the fix moves on the GPS map, `plan` holds the rest of
the route (LiveMap draws it), a `mission` diagnostic says "waypoint 2 of 4", and the log says when
each waypoint is reached. As with a single goal, the operator wins: any cmd_vel (the e-stop's
zero included) or a new goal cancels the mission, and so does a wall the robot cannot get past.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from std_msgs.msg import Float64MultiArray

from .geodesy import geodetic_to_enu


def mission_points(data: Sequence[float]) -> list[tuple[float, float]]:
    """[(lng, lat), ...] from the flat array; ValueError says what is wrong with it."""
    values = [float(v) for v in data]
    if not values or len(values) % 2:
        raise ValueError(f"expected [lng, lat, lng, lat, ...], got {len(values)} numbers")
    points = list(zip(values[::2], values[1::2], strict=True))
    for i, (lng, lat) in enumerate(points):
        if not (math.isfinite(lng) and math.isfinite(lat) and -180 <= lng <= 180 and -90 <= lat <= 90):
            raise ValueError(f"waypoint {i + 1} is not a position: lng {lng}, lat {lat}")
    return points


class Mission:
    """Waypoints in the map frame and which one the robot is driving to. Pure."""

    def __init__(self, points: Sequence[tuple[float, float]]):
        self.points = list(points)
        self.index = 0

    @property
    def total(self) -> int:
        return len(self.points)

    @property
    def done(self) -> bool:
        return self.index >= len(self.points)

    def goal(self, x: float, y: float) -> tuple[float, float, float]:
        """The current waypoint and the heading to arrive with: along the next leg, else along the last one."""
        gx, gy = self.points[self.index]
        if self.index + 1 < len(self.points):
            nx, ny = self.points[self.index + 1]
            return gx, gy, math.atan2(ny - gy, nx - gx)
        px, py = self.points[self.index - 1] if self.index else (x, y)
        return gx, gy, math.atan2(gy - py, gx - px) if (gx, gy) != (px, py) else 0.0

    def beyond(self) -> list[tuple[float, float]]:
        """The waypoints after the current one."""
        return self.points[self.index + 1:]


class MissionDriver:
    """A RoverSim's mission: listens on `mission` and feeds the node's goal follower."""

    def __init__(self, node):
        self.node = node
        self.mission: Mission | None = None
        self.last = "no mission yet"
        node.create_subscription(Float64MultiArray, "mission", self._on_mission, 10)

    @property
    def active(self) -> bool:
        return self.mission is not None

    def _on_mission(self, msg) -> None:
        node, log = self.node, self.node.get_logger()
        try:
            points = mission_points(msg.data)
        except ValueError as exc:
            log.warning(f"ignoring a mission: {exc}")
            return
        self.mission = Mission([geodetic_to_enu(lat, lng, node.lat0, node.lon0) for lng, lat in points])
        log.info(f"mission of {len(points)} waypoints received: driving to waypoint 1")
        node.follower.cancel()
        self._next()

    def _next(self) -> None:
        mission, node = self.mission, self.node
        node.follower.set_goal(*mission.goal(node.drive.x, node.drive.y))
        self.last = f"driving to waypoint {mission.index + 1} of {mission.total}"
        node.plan_pub.publish(node._plan(node.follower.goal))

    def reached(self) -> bool:
        """The goal follower arrived; True if that was a mission's waypoint (then the next one is the goal)."""
        mission, log = self.mission, self.node.get_logger()
        if mission is None:
            return False
        mission.index += 1
        log.info(f"mission: waypoint {mission.index} of {mission.total} reached")
        if mission.done:
            log.info(f"mission complete: {mission.total} waypoints")
            self.mission, self.last = None, f"complete: {mission.total} waypoints"
            self.node.plan_pub.publish(self.node._plan(None))
        else:
            self._next()
        return True

    def cancel(self, why: str) -> None:
        mission = self.mission
        if mission is not None:
            self.node.get_logger().info(f"mission cancelled at waypoint {mission.index + 1} of {mission.total}: {why}")
            self.mission, self.last = None, f"cancelled at waypoint {mission.index + 1} of {mission.total}: {why}"

    def beyond(self) -> list[tuple[float, float]]:
        return self.mission.beyond() if self.mission else []

    def status(self, name: str) -> dict:
        """A diagnostic status (health.py's plain form) the Diagnostics page shows."""
        mission = self.mission
        values = {"waypoint": f"{mission.index + 1}", "of": f"{mission.total}"} if mission else {}
        return {"name": f"{name}: mission", "hardware_id": "navigation", "level": 0,
                "message": self.last, "values": values}
