"""Nav2's navigation goals of one robot: send, follow, cancel; and its servers' lifecycle states.

One goal at a time, as bt_navigator runs one: a new goal (of any of the three actions) replaces
the one shown, and Nav2 preempts it. The state (the goal, its last feedback, its result, the
servers) is one dict, published whole on the `nav2` channel at most ROVER_WEB_NAV2_FEEDBACK_MAX_HZ
(the hub always ends on the latest, so a result is never lost behind feedback) and answered by
GET /api/nav2.

Cancelled by: the operator (POST /api/nav2/cancel), the e-stop (its engage hook, besides the
canceller's CancelGoal to every goal of every navigation action), the sender's credentials ending
(auth's revocation: the sender's token revoked, session ended, role lowered) and shutdown.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any

from rover_web.core.state import Rover
from rover_web.estop import EStopService
from rover_web.web.api_messages import explain, text_of, with_wire

from . import msgs

log = logging.getLogger(__name__)

CHANNEL = "nav2"
DISCOVERY_S = 3.0  # a GetState client younger than this that has no server yet says "checking", not "missing"
CANCEL_BY = {"operator", "e-stop", "revocation", "shutdown"}


class Nav2Unavailable(RuntimeError):
    """nav2_msgs is missing (503), or no action server answers (503)."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


class GoalRejected(RuntimeError):
    """The action server said no (409)."""


class NoGoal(RuntimeError):
    """Nothing to cancel (409)."""


class ShuttingDown(RuntimeError):
    pass


class Nav2Service:
    def __init__(self, rover: Rover, estop: EStopService):
        self.rover = rover
        self.estop = estop
        config = rover.config
        self.goal_mode = config["ROVER_WEB_NAV2_GOAL_MODE"]
        self.timeout_s = config["ROVER_WEB_NAV2_TIMEOUT_S"]
        self.max_hz = config["ROVER_WEB_NAV2_FEEDBACK_MAX_HZ"]
        self.frame_id = config["ROVER_WEB_GOAL_FRAME_ID"]
        self.max_poses = config["ROVER_WEB_NAV2_MAX_POSES"]
        self.actions = {kind: rover.resolve(f"/{name}") for kind, (name, _) in msgs.ACTIONS.items()}
        self.lifecycle_nodes = [rover.resolve(n if n.startswith("/") else f"/{n}")
                                for n in config["ROVER_WEB_NAV2_LIFECYCLE_NODES"]]
        self.missing = msgs.missing()
        self._client = None
        self._client_lock = threading.Lock()
        self._lock = threading.Lock()
        self._goal: dict | None = None  # the goal shown: its plain values
        self._handle = None
        self._registration = None  # auth's revocation registration of the goal's sender
        self._feedback: dict | None = None
        self._result: dict | None = None
        self._lifecycle: dict[str, dict] = {n: {"node": n, "state": "unknown", "checked": None}
                                            for n in self.lifecycle_nodes}
        self._lifecycle_since: float | None = None
        self._servers_seen: tuple | None = None
        self.watching = threading.Event()  # set once the client exists: the lifecycle loop runs then
        estop.on_engage(lambda by: self.cancel_active("e-stop", f"the e-stop was engaged by {by}"))

    # --- the client: made at first use ---

    def client(self):
        if self._client is None:
            with self._client_lock:
                if self._client is None:
                    from rover_web.ros.goal_client import GoalClient

                    if self.missing is None:
                        self.missing = msgs.missing(load=True)  # found at start; loaded only now

                    self._client = GoalClient(self.rover.runtime, self.rover.robot.namespace)
                    if self.missing is None:
                        for kind, name in self.actions.items():  # discovery starts now, not at the first goal
                            self._client.action(msgs.action_type(kind), name)
                    self._lifecycle_since = time.monotonic()
                    self.watching.set()
        return self._client

    def close(self) -> None:
        self.cancel_active("shutdown", "rover_web is shutting down")

    # --- state ---

    @property
    def missing_text(self):
        """Why Nav2 cannot be used (a Text, translated in an answer), or None."""
        return self.missing

    def goal_via(self) -> str:
        """How LiveMap sends a goal now: 'action' (NavigateToPose) or 'topic' (ROVER_WEB_GOAL_TOPIC)."""
        if self.goal_mode == "topic":
            return "topic"
        if self.goal_mode == "action":
            return "action"
        if self.missing is not None or self._client is None:
            return "topic"
        return "action" if self._client.server_ready(self.actions["to_pose"]) else "topic"

    def state(self) -> dict:
        client = self._client
        with self._lock:
            goal = dict(self._goal) if self._goal else None
            feedback, result = self._feedback, self._result
            lifecycle = [dict(v) for v in self._lifecycle.values()]
        return {
            "available": self.missing is None,
            "missing": (None if self.missing is None
                        else with_wire({"packages": ["nav2_msgs"], "message": self.missing})),
            "goal_mode": self.goal_mode, "goal_via": self.goal_via(),
            "servers": {kind: {"action": name, "ready": bool(client and self.missing is None
                                                             and client.server_ready(name))}
                        for kind, name in self.actions.items()},
            "lifecycle": lifecycle,
            "goal": goal, "feedback": feedback, "result": result,
        }

    def publish(self) -> None:
        self.rover.hub.publish_throttled(CHANNEL, self.state(), self.max_hz)

    # --- goals ---

    def send(self, kind: str, poses: list[tuple[float, float, float]], *, map_name: str, by: str,
             watch=None) -> dict:
        """Send a goal of `kind` through `poses` (already checked against the map and its keep-out areas).

        `watch(close)` registers the request's credential with auth's revocation (on_revoke)."""
        if self.missing is not None:
            raise Nav2Unavailable("nav2_unavailable", self.missing_text)
        if self.rover.stopping.is_set():
            raise ShuttingDown(explain("the server is shutting down; no goal was sent"))
        self.estop.check_motion()
        client = self.client()
        from rover_web.ros.goal_client import NoAnswer

        stamp = self.rover.runtime.now_msg()
        message = msgs.goal(kind, poses, self.frame_id, stamp)
        record = {"id": None, "kind": kind, "action": self.actions[kind], "map": map_name,
                  "frame_id": self.frame_id,
                  "poses": [{"x": x, "y": y, "yaw": round(yaw, 6)} for x, y, yaw in poses],
                  "sent_by": by, "sent_at": time.time(), "status": "sending", "cancel": None}
        holder: dict[str, Any] = {}

        def on_feedback(feedback) -> None:
            values = msgs.feedback(kind, feedback)
            with self._lock:
                if self._goal is None or self._goal["id"] != holder.get("id"):
                    return
                self._feedback = values
                if self._goal["status"] == "accepted":
                    self._goal["status"] = "executing"
            self.publish()

        def on_result(status: str, result) -> None:
            values = {"status": status, **(msgs.result(kind, result) if result is not None else
                                           {"error_code": None, "error_name": None,
                                            "error_msg": "the action server went away before it answered"})}
            values["goal_id"] = holder.get("id")
            with self._lock:
                if self._goal is None or self._goal["id"] != holder.get("id"):
                    log.info("nav2: an earlier goal ended %s", status)
                    return
                self._goal["status"] = status
                self._goal["ended_at"] = time.time()
                if status == "canceled" and self._goal["cancel"] is None:
                    # Canceled by a CancelGoal not sent from here: while the e-stop is engaged, its
                    # canceller's (it cancels every goal, and Nav2 may answer before the e-stop's
                    # hooks have reached this feature's).
                    by = "e-stop" if self.estop.engaged else "another client"
                    self._goal["cancel"] = {"by": by, "reason": f"canceled by {by}'s CancelGoal", "at": time.time(),
                                            "answer": "canceled"}
                self._result = values
                self._handle = None
                registration, self._registration = self._registration, None
            if registration is not None:
                registration.cancel()
            log.info("nav2: %s goal %s: %s %s", kind, status, values.get("error_code"), values.get("error_msg"))
            self.publish()

        if (not client.server_ready(self.actions[kind])
                and time.monotonic() - (self._lifecycle_since or 0.0) > DISCOVERY_S):
            # Discovery has had its time: no server now is no Nav2, not a slow one (no 3 s wait per click).
            raise Nav2Unavailable("no_nav2_server", explain("no action server for %(actions)s: is Nav2 running "
                                                            "(bt_navigator active)?",
                                                            actions=self.actions[kind]))
        try:
            sent = client.send_goal(msgs.action_type(kind), self.actions[kind], message, self.timeout_s,
                                    on_feedback, on_result)
        except NoAnswer as exc:
            raise Nav2Unavailable("no_nav2_server", explain("%(why)s: is Nav2 running (bt_navigator active)?",
                                                            why=text_of(exc))) from None
        if sent is None:
            raise GoalRejected(explain("%(actions)s rejected the goal", actions=self.actions[kind]))
        goal_id, handle = sent
        holder["id"] = goal_id
        record["id"] = goal_id
        record["status"] = "accepted"
        registration = watch(lambda reason: self.cancel_active("revocation", f"the sender's access ended: {reason}",
                                                                goal_id)) if watch else None
        with self._lock:
            previous = self._registration
            self._goal, self._handle, self._feedback, self._result = record, handle, None, None
            self._registration = registration
        if previous is not None:
            previous.cancel()
        if self.estop.engaged:  # engaged while the goal was on its way: its hook ran before the handle was known
            self.cancel_active("e-stop", "the e-stop was engaged while the goal was sent", goal_id)
        self.publish()
        log.info("nav2: %s goal %s sent by %s (%d poses)", kind, goal_id, by, len(poses))
        return dict(record)

    def cancel_active(self, by: str, reason: str, goal_id: str | None = None) -> dict | None:
        """Ask Nav2 to cancel the goal shown (only `goal_id`, if given); never waits. None if there is none."""
        with self._lock:
            goal, handle = self._goal, self._handle
            if goal is None or handle is None or (goal_id is not None and goal["id"] != goal_id):
                return None
            goal["cancel"] = {"by": by, "reason": reason, "at": time.time(), "answer": None}
            goal["status"] = "canceling"
            registration, self._registration = self._registration, None
        if registration is not None and by != "revocation":
            registration.cancel()
        log.warning("nav2: canceling goal %s (%s: %s)", goal["id"], by, reason)

        def answered(outcome: str) -> None:
            with self._lock:
                if self._goal is goal and goal["cancel"] is not None:
                    goal["cancel"]["answer"] = outcome
            self.publish()

        self._client.cancel(handle, answered)
        self.publish()
        return dict(goal)

    # --- lifecycle ---

    def poll_lifecycle(self) -> None:
        """Every ROVER_WEB_NAV2_LIFECYCLE_PERIOD_S once the client exists: GetState of each Nav2 server."""
        client = self._client
        if client is None:
            return
        srv = msgs.get_state_type()
        young = time.monotonic() - (self._lifecycle_since or 0.0) < DISCOVERY_S
        changed = False
        for node in self.lifecycle_nodes:
            def answered(response, node=node) -> None:
                state = "no_answer" if response is None else msgs.lifecycle_state(response)
                with self._lock:
                    entry = self._lifecycle[node]
                    moved = entry["state"] != state
                    entry.update(state=state, checked=time.time())
                if moved:
                    self.publish()

            if not client.call(srv, f"{node}/get_state", srv.Request(), answered):
                state = "checking" if young else "missing"
                with self._lock:
                    entry = self._lifecycle[node]
                    changed |= entry["state"] != state
                    entry.update(state=state, checked=time.time())
        servers = (self.goal_via(), tuple(client.server_ready(n) for n in self.actions.values()))
        if changed or servers != self._servers_seen:  # a Nav2 that came up (or went) shows without a goal
            self._servers_seen = servers
            self.publish()
