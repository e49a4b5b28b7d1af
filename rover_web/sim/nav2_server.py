"""The simulated robot answers Nav2's navigation actions as Nav2 would (nav2_msgs, Jazzy).

  navigate_to_pose        NavigateToPose: plan around the walls (planner.py), drive it, feedback
                          (current_pose, navigation_time, estimated_time_remaining, number_of_recoveries,
                          distance_remaining), cancel; aborted with the planner's error code when unreachable
  navigate_through_poses  NavigateThroughPoses: one path through every pose, stopping only at the last
  follow_waypoints        FollowWaypoints: each pose in turn, stopping at each; feedback current_waypoint;
                          a waypoint it cannot reach is missed (missed_waypoints, with the planner's code) and
                          the next one driven; none reached: aborted, TASK_EXECUTOR_FAILED
  <node>/get_state        lifecycle_msgs/GetState for bt_navigator, planner_server and the rest: active

Like bt_navigator, a new goal of any of the three preempts the running one (aborted), and so do a
goal on goal_pose and a GPS mission. The operator wins as with every goal of the simulator: a
non-zero cmd_vel aborts the goal ("operator took over"). A zero cmd_vel holds the robot still for
as long as zeros keep coming (the e-stop's hold) without ending the goal: the e-stop cancels it
with CancelGoal, as it would on a real robot. A robot that makes no headway (a wall the plan did
not know) replans; after REPLAN_LIMIT recoveries the goal is aborted with FollowPath's
FAILED_TO_MAKE_PROGRESS.

Without nav2_msgs (no wheel on PyPI: scripts/build_interfaces.sh) the simulator runs without these.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from builtin_interfaces.msg import Duration
from geometry_msgs.msg import PoseStamped
from lifecycle_msgs.msg import State
from lifecycle_msgs.srv import GetState
from nav_msgs.msg import Path

from rover_web.ros.convert import quaternion_from_yaw, yaw_from_quaternion

from .planner import GridPlanner, PlanError, path_length
from .walls import StallWatch

# What nav2_bringup's navigation and localisation launch files start (lifecycle-managed).
LIFECYCLE_NODES = ("map_server", "amcl", "controller_server", "smoother_server", "planner_server", "behavior_server",
                   "velocity_smoother", "collision_monitor", "bt_navigator", "waypoint_follower")
PASS_M = 0.15           # an inner corner counts as passed this close: the robot arcs on, it does not stop there
FEEDBACK_PERIOD_S = 0.05  # bt_navigator sends feedback every BT tick; 20 Hz is plenty for a GUI to bound
PLAN_PERIOD_S = 1.0
REPLAN_LIMIT = 3

# nav2_msgs result codes (Jazzy)
NAVIGATE_UNKNOWN = 9000          # NavigateToPose / NavigateThroughPoses
FAILED_TO_MAKE_PROGRESS = 105    # FollowPath
TASK_EXECUTOR_FAILED = 601       # FollowWaypoints: no waypoint could be reached


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


class PlanDrive:
    """Drives a planned path: turn-and-drive legs between its corners, passing through inner corners,
    stopping at the last with `final_yaw`. Pure, so it is unit-tested."""

    def __init__(self, points: list[tuple[float, float]], final_yaw: float, follower):
        self.points = points
        self.final_yaw = final_yaw
        self.follower = follower  # a GoalFollower (rover.py)
        self.index = 1 if len(points) > 1 else 0
        self._aim()

    def _aim(self) -> None:
        x, y = self.points[self.index]
        if self.index == len(self.points) - 1:
            yaw = self.final_yaw
        else:
            nx, ny = self.points[self.index + 1]
            yaw = math.atan2(ny - y, nx - x)
        self.follower.set_goal(x, y, yaw)

    @property
    def done(self) -> bool:
        return not self.follower.active

    def command(self, x: float, y: float, yaw: float) -> tuple[float, float]:
        while self.index < len(self.points) - 1 and math.hypot(self.points[self.index][0] - x,
                                                               self.points[self.index][1] - y) < PASS_M:
            self.index += 1
            self._aim()
        return self.follower.command(x, y, yaw)

    def remaining(self, x: float, y: float) -> list[tuple[float, float]]:
        """The path still to drive, from the robot."""
        return [] if self.done else [(x, y), *self.points[self.index:]]

    def distance_remaining(self, x: float, y: float) -> float:
        return path_length(self.remaining(x, y))


@dataclass
class Job:
    kind: str  # to_pose | through_poses | waypoints
    handle: object
    targets: list[tuple[float, float, float]]
    done: object  # rclpy Future: the result message the execute coroutine returns
    started: float
    index: int = 0  # the first target not yet reached
    drive: PlanDrive | None = None
    ends: list[int] = field(default_factory=list)  # through_poses: each target's index in the drive's points
    missed: list[tuple[int, int, str]] = field(default_factory=list)  # waypoints: (index, code, message)
    recoveries: int = 0
    stall: StallWatch = field(default_factory=StallWatch)
    hold_until: float = -math.inf
    last_feedback: float = -math.inf
    last_plan: float = -math.inf


class Nav2Sim:
    def __init__(self, node, walls, speed_mps: float):
        from rclpy.task import Future

        self._future = Future
        self.node = node
        self.planner = GridPlanner(walls)
        self.speed_mps = speed_mps
        self.job: Job | None = None
        self.available = False
        try:
            from nav2_msgs.action import FollowWaypoints, NavigateThroughPoses, NavigateToPose
            from nav2_msgs.msg import MissedWaypoint
        except ImportError:
            node.get_logger().warning("nav2_msgs is not installed: no Nav2 actions in this simulator "
                                      "(build it with scripts/build_interfaces.sh)")
            return
        from rclpy.action import ActionServer, CancelResponse

        self._types = {"to_pose": NavigateToPose, "through_poses": NavigateThroughPoses, "waypoints": FollowWaypoints}
        self._missed_waypoint = MissedWaypoint
        names = {"to_pose": "navigate_to_pose", "through_poses": "navigate_through_poses",
                 "waypoints": "follow_waypoints"}
        self._servers = [
            ActionServer(node, self._types[kind], name,
                         execute_callback=self._executor_of(kind),
                         cancel_callback=lambda _handle: CancelResponse.ACCEPT)
            for kind, name in names.items()]
        self._lifecycle = [node.create_service(GetState, f"{name}/get_state", self._get_state)
                           for name in LIFECYCLE_NODES]
        self.available = True

    @property
    def active(self) -> bool:
        return self.job is not None

    # --- lifecycle ---

    @staticmethod
    def _get_state(_request, response):
        response.current_state = State(id=State.PRIMARY_STATE_ACTIVE, label="active")
        return response

    # --- goals ---

    def _executor_of(self, kind: str):
        async def execute(handle):  # a coroutine function: rclpy awaits it on the executor, not a thread
            return await self._execute(handle, kind)
        return execute

    async def _execute(self, handle, kind: str):
        request = handle.request
        poses = [request.pose] if kind == "to_pose" else list(request.poses)
        targets = []
        for pose in poses:
            p, q = pose.pose.position, pose.pose.orientation
            targets.append((p.x, p.y, yaw_from_quaternion(q.x, q.y, q.z, q.w)))
        frames = {pose.header.frame_id for pose in poses} - {"map", ""}
        bad = (not targets or frames or not all(math.isfinite(v) for t in targets for v in t))
        if self.job is not None:
            self._finish(self.job, "abort", NAVIGATE_UNKNOWN, "preempted by a new goal")
        if bad:
            why = (f"poses in frame {sorted(frames)[0]!r}; the simulator drives in 'map'" if frames
                   else "no poses" if not targets else "a pose that is not finite")
            self.node.get_logger().warning(f"Nav2 goal refused: {why}")
            handle.abort()
            return self._result(kind, TASK_EXECUTOR_FAILED if kind == "waypoints" else NAVIGATE_UNKNOWN, why)
        self.node.follower.cancel()
        self.node.mission.cancel("a Nav2 goal")
        job = Job(kind, handle, targets, self._future(), time.monotonic())
        if kind == "waypoints":
            job.index = min(int(request.goal_index), len(targets))
        d = self.node.drive
        try:
            self._plan(job, d.x, d.y)
        except PlanError as exc:
            if kind != "waypoints":
                self.node.get_logger().warning(f"Nav2 goal aborted: {exc}")
                handle.abort()
                self.node.plan_pub.publish(self._path([]))
                return self._result(kind, exc.code, str(exc))
            self._miss(job, exc)
            if not self._next_waypoint(job, d.x, d.y):
                handle.abort()
                return self._result(kind, TASK_EXECUTOR_FAILED, "no waypoint could be reached", job.missed, targets)
        self.job = job
        self.node.get_logger().info(f"Nav2 {kind} goal accepted: {len(targets)} pose(s)")
        return await job.done

    def _plan(self, job: Job, x: float, y: float) -> None:
        """A drive from (x, y) to the job's next target (through every remaining one for through_poses)."""
        from .rover import GoalFollower

        remaining = job.targets[job.index:] if job.kind == "through_poses" else [job.targets[job.index]]
        points: list[tuple[float, float]] = [(x, y)]
        ends = []
        for tx, ty, _ in remaining:
            leg = self.planner.plan(points[-1], (tx, ty))
            points.extend(leg[1:])
            ends.append(len(points) - 1)
        job.ends = ends
        job.drive = PlanDrive(points, remaining[-1][2], GoalFollower(max_linear_mps=self.speed_mps))
        job.stall = StallWatch()
        job.last_plan = -math.inf

    def _miss(self, job: Job, exc: PlanError) -> None:
        self.node.get_logger().warning(f"waypoint {job.index} missed: {exc}")
        job.missed.append((job.index, exc.code, str(exc)))

    def _next_waypoint(self, job: Job, x: float, y: float) -> bool:
        """Move on to the next reachable waypoint; False when none is left."""
        while True:
            job.index += 1
            if job.index >= len(job.targets):  # number_of_loops is not simulated: one pass
                return False
            try:
                self._plan(job, x, y)
                return True
            except PlanError as exc:
                self._miss(job, exc)

    def preempt(self, why: str) -> None:
        """Something else takes the robot (a goal on goal_pose, a mission): the Nav2 goal is aborted."""
        if self.job is not None:
            self._finish(self.job, "abort", NAVIGATE_UNKNOWN, f"preempted by {why}")

    def operator_command(self, linear: float, angular: float, now: float) -> None:
        job = self.job
        if job is None:
            return
        if linear == 0.0 and angular == 0.0:
            job.hold_until = now + self.node.drive.cmd_timeout_s  # a held stop (the e-stop's zeros)
        else:
            self._finish(job, "abort", NAVIGATE_UNKNOWN, "the operator took over (cmd_vel)")

    # --- each tick ---

    def tick(self, x: float, y: float, yaw: float, linear: float, now: float) -> tuple[float, float] | None:
        """The command to drive now, None while the operator holds the robot; ends the goal when it is done."""
        job = self.job
        if job is None:
            return None
        if job.handle.is_cancel_requested:
            self._finish(job, "cancel", 0, "")
            return 0.0, 0.0
        if now < job.hold_until:
            job.stall = StallWatch()
            self._feedback(job, x, y, linear, now)
            return None
        command = job.drive.command(x, y, yaw)
        if job.kind == "through_poses":
            while job.index < len(job.targets) - 1 and job.drive.index > job.ends[0]:
                job.index += 1
                job.ends.pop(0)
        if job.drive.done:
            if job.kind != "waypoints":
                self._finish(job, "succeed", 0, "")
                return 0.0, 0.0
            self.node.get_logger().info(f"waypoint {job.index} reached")
            if not self._next_waypoint(job, x, y):
                all_missed = len(job.missed) == len(job.targets)
                self._finish(job, "abort" if all_missed else "succeed",
                             TASK_EXECUTOR_FAILED if all_missed else 0,
                             "no waypoint could be reached" if all_missed else "")
                return 0.0, 0.0
            command = job.drive.command(x, y, yaw)
        if job.stall.stalled(x, y, now, pushing=abs(linear) > 0.05):
            job.recoveries += 1
            if job.recoveries > REPLAN_LIMIT:
                self._finish(job, "abort", FAILED_TO_MAKE_PROGRESS,
                             f"no progress at ({x:.2f}, {y:.2f}) after {REPLAN_LIMIT} recoveries")
                return 0.0, 0.0
            self.node.get_logger().warning(f"no progress at ({x:.2f}, {y:.2f}): replanning")
            try:
                self._plan(job, x, y)
            except PlanError as exc:
                self._finish(job, "abort", exc.code, str(exc))
                return 0.0, 0.0
        self._feedback(job, x, y, linear, now)
        if now - job.last_plan >= PLAN_PERIOD_S:  # a planner republishes its path; ours shrinks as we go
            job.last_plan = now
            self.node.plan_pub.publish(self._path(job.drive.remaining(x, y)))
        return command

    def _feedback(self, job: Job, x: float, y: float, linear: float, now: float) -> None:
        if now - job.last_feedback < FEEDBACK_PERIOD_S:
            return
        job.last_feedback = now
        feedback = self._types[job.kind].Feedback()
        if job.kind == "waypoints":
            feedback.current_waypoint = job.index
        else:
            distance = job.drive.distance_remaining(x, y)
            feedback.current_pose = self._pose(x, y, self.node.drive.yaw)
            feedback.navigation_time = _duration(now - job.started)
            # As bt_navigator: the distance over the current speed (over the top speed when standing).
            speed = abs(linear) if abs(linear) > 0.05 else self.speed_mps
            feedback.estimated_time_remaining = _duration(distance / speed)
            feedback.number_of_recoveries = job.recoveries
            feedback.distance_remaining = float(distance)
            if job.kind == "through_poses":
                feedback.number_of_poses_remaining = len(job.targets) - job.index
        job.handle.publish_feedback(feedback)

    def _finish(self, job: Job, how: str, code: int, message: str) -> None:
        self.job = None
        handle = job.handle
        if how == "succeed":
            handle.succeed()
            self.node.get_logger().info(f"Nav2 {job.kind} goal succeeded")
        elif how == "cancel":
            handle.canceled()
            self.node.get_logger().info(f"Nav2 {job.kind} goal canceled")
        else:
            handle.abort()
            self.node.get_logger().warning(f"Nav2 {job.kind} goal aborted: {message}")
        self.node.plan_pub.publish(self._path([]))
        job.done.set_result(self._result(job.kind, code, message, job.missed, job.targets))

    # --- messages ---

    def _result(self, kind: str, code: int, message: str, missed=(), targets=()):
        result = self._types[kind].Result()
        result.error_code = code
        if hasattr(result, "error_msg"):
            result.error_msg = message
        if kind == "waypoints":
            for index, wcode, _message in missed:  # MissedWaypoint has no room for the message (Jazzy)
                result.missed_waypoints.append(
                    self._missed_waypoint(index=index, goal=self._pose(*targets[index]), error_code=wcode))
        return result

    def _pose(self, x: float, y: float, yaw: float) -> PoseStamped:
        pose = PoseStamped()
        pose.header.stamp = self.node.get_clock().now().to_msg()
        pose.header.frame_id = "map"
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        o = pose.pose.orientation
        o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
        return pose

    def _path(self, points: list[tuple[float, float]]) -> Path:
        msg = Path()
        msg.header.stamp = self.node.get_clock().now().to_msg()
        msg.header.frame_id = "map"
        for x0, y0, x1, y1 in ((*a, *b) for a, b in zip(points, points[1:], strict=False)):
            steps = max(1, int(math.hypot(x1 - x0, y1 - y0) / 0.25))
            for i in range(0 if not msg.poses else 1, steps + 1):
                msg.poses.append(self._pose(x0 + (x1 - x0) * i / steps, y0 + (y1 - y0) * i / steps, 0.0))
        return msg


def _duration(seconds: float) -> Duration:
    seconds = max(0.0, seconds) if math.isfinite(seconds) else 0.0
    whole = int(seconds)
    return Duration(sec=whole, nanosec=int((seconds - whole) * 1e9))
