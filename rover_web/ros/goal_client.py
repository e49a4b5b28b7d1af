"""One robot's navigation goals and the services watched beside them, on a node of their own.

Nav2's action clients (navigate_to_pose and friends) and the lifecycle GetState clients of its
servers live on a SideNode (`<app node>_nav2`, in the robot's namespace) with its own executor
thread, as the e-stop's canceller and /ros's admin node do. Each action client is five waitables
(three services, the feedback and status subscriptions) that the main executor would rebuild into
its wait set on every wake-up (100 Hz odometry and more), and Nav2 sends feedback at its BT rate
(up to 100 Hz): here it wakes only this thread, and the feature decides what reaches browsers.

Request threads send and wait on futures with timeouts; callbacks run on this node's thread with
the raw messages, which the feature's msgs.py reads. The node is made at the first use, not at
start (a robot nobody navigates from the GUI pays nothing).
"""

from __future__ import annotations

import threading
import uuid
from collections.abc import Callable
from typing import Any

from rover_web.web.api_messages import explain

from .actions import cancel_if_accepted
from .side_node import SideNode

GOAL_STATUS = {0: "unknown", 1: "accepted", 2: "executing", 3: "canceling", 4: "succeeded", 5: "canceled",
               6: "aborted"}
CANCEL_CODES = {0: "canceling", 1: "rejected", 2: "unknown_goal", 3: "terminated"}


class NoAnswer(TimeoutError):
    """No server, or no answer within the timeout."""


class GoalClient:
    def __init__(self, runtime, namespace: str = ""):
        from rclpy.action import ActionClient

        self._action_client = ActionClient
        self._side = SideNode(runtime, "nav2", namespace=namespace)
        self._node = self._side.node
        self._actions: dict[str, Any] = {}
        self._services: dict[str, Any] = {}
        self._lock = threading.Lock()

    def close(self) -> None:
        self._side.close()

    def action(self, action_cls: type, name: str):
        with self._lock:
            client = self._actions.get(name)
            if client is None:
                client = self._actions[name] = self._action_client(self._node, action_cls, name)
        return client

    def server_ready(self, name: str) -> bool:
        client = self._actions.get(name)
        return client is not None and client.server_is_ready()

    def _wait(self, future, timeout_s: float, what: str):
        done = threading.Event()
        future.add_done_callback(lambda _f: done.set())
        self._side.wake()
        if not done.wait(timeout_s):
            raise NoAnswer(explain("%(what)s did not answer within %(timeout_s)s s",
                                   what=what, timeout_s=format(timeout_s, "g")))
        return future.result()

    def send_goal(self, action_cls: type, name: str, goal, timeout_s: float,
                  on_feedback: Callable[[Any], None], on_result: Callable[[str, Any], None]) -> tuple[str, Any] | None:
        """(goal id as hex, handle) once accepted; None when the server rejected it; NoAnswer without a server.

        `on_feedback(feedback message)` and `on_result(status, result message or None)` run on this node's thread.
        """
        client = self.action(action_cls, name)
        if not client.wait_for_server(timeout_sec=timeout_s):
            raise NoAnswer(explain("no action server for %(name)s answered within %(timeout_s)s s",
                                   name=name, timeout_s=format(timeout_s, "g")))
        sending = client.send_goal_async(goal, feedback_callback=lambda msg: on_feedback(msg.feedback))
        try:
            handle = self._wait(sending, timeout_s, name)
        except NoAnswer:
            cancel_if_accepted(sending)
            self._side.wake()
            raise
        if not handle.accepted:
            return None

        def finished(future) -> None:
            try:
                wrapped = future.result()
                on_result(GOAL_STATUS.get(wrapped.status, "unknown"), wrapped.result)
            except Exception:  # the server went away
                on_result("unknown", None)

        handle.get_result_async().add_done_callback(finished)
        self._side.wake()
        return uuid.UUID(bytes=bytes(handle.goal_id.uuid)).hex, handle

    def cancel(self, handle, on_done: Callable[[str], None] | None = None) -> None:
        """Ask the server to cancel the goal without waiting; `on_done(outcome)` when it answers."""
        future = handle.cancel_goal_async()
        if on_done is not None:
            def answered(f) -> None:
                try:
                    on_done(CANCEL_CODES.get(f.result().return_code, "error"))
                except Exception:
                    on_done("error")

            future.add_done_callback(answered)
        self._side.wake()

    def call(self, srv_cls: type, name: str, request, on_done: Callable[[Any | None], None]) -> bool:
        """Call a service without waiting; False (and no call) when no server is there now.
        `on_done(response or None)` on this node's thread."""
        with self._lock:
            client = self._services.get(name)
            if client is None:
                client = self._services[name] = self._node.create_client(srv_cls, name)
        if not client.service_is_ready():
            return False
        future = client.call_async(request)

        def answered(f) -> None:
            try:
                on_done(f.result())
            except Exception:
                on_done(None)

        future.add_done_callback(answered)
        self._side.wake()
        return True
