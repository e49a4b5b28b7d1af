"""Cancelling every goal of running action servers (Nav2's navigate_to_pose and friends).

An action server answers `action_msgs/srv/CancelGoal` on `<action>/_action/cancel_goal`; a
request with a zero goal id and a zero stamp cancels every goal it has accepted. Clients are made
once, at start, so that discovery has happened long before an e-stop needs them.

They live on a small node of their own (`<app node>_estop`) with its own executor thread: on the
app's node, rclpy would rebuild them into the main executor's wait set at every wake-up (100 Hz
odometry and more), for a call made only when someone hits the e-stop (bench/events.py showed a
p99 0.6 ms worse). Idle, their executor blocks and costs nothing.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from action_msgs.srv import CancelGoal

from .side_node import SideNode

RETURN_CODES = {0: "canceled", 1: "rejected", 2: "no_goals", 3: "no_goals"}  # 2, 3: nothing to cancel


def cancel_if_accepted(sending) -> None:
    """When a send_goal_async future the caller stopped waiting for completes with an accepted goal,
    cancel that goal: it would otherwise run with nobody watching it (the caller was told there
    was no answer)."""
    def done(future) -> None:
        late = None if future.exception() else future.result()
        if late is not None and late.accepted:
            late.cancel_goal_async()

    sending.add_done_callback(done)


class GoalCanceller:
    def __init__(self, runtime, actions: list[str], namespace: str = ""):
        # In the robot's namespace: each robot's canceller is a node of its own name (/boat/rover_web_estop).
        self._side = SideNode(runtime, "estop", namespace=namespace)
        self._node = self._side.node
        self._clients = {name: self._node.create_client(CancelGoal, f"{name.rstrip('/')}/_action/cancel_goal")
                         for name in actions}

    def close(self) -> None:
        self._side.close()

    @property
    def actions(self) -> list[str]:
        return list(self._clients)

    def running(self) -> list[str]:
        """The actions whose server this node can reach now: the ones an engage would cancel."""
        return [name for name, client in self._clients.items() if client.service_is_ready()]

    def cancel_all(self, on_done: Callable[[list[dict]], None], timeout_s: float = 1.0) -> None:
        """Ask every running action server to cancel all its goals, without waiting for the answers:
        `on_done` gets one outcome per action when all have answered or `timeout_s` has passed, and
        again with every answer that comes after that (a loaded robot's server may answer late:
        its `no_answer` then becomes what it did)."""
        outcomes: dict[str, dict] = {}
        pending: list = []
        lock = threading.Lock()
        finished = threading.Event()

        def finish() -> None:
            with lock:
                if finished.is_set():
                    return
                finished.set()
                for name, _ in pending:
                    outcomes.setdefault(name, {"action": name, "result": "no_answer"})
                result = [outcomes[name] for name in self._clients]
            on_done(result)

        for name, client in self._clients.items():
            if not client.service_is_ready():
                outcomes[name] = {"action": name, "result": "not_running"}
                continue
            future = client.call_async(CancelGoal.Request())  # zero id, zero stamp: every goal
            pending.append((name, future))

        def answered(name: str, future) -> None:
            try:
                response = future.result()
                outcome = {"action": name, "result": RETURN_CODES.get(response.return_code, "error"),
                           "goals": len(response.goals_canceling)}
            except Exception as exc:  # the server vanished mid-call
                outcome = {"action": name, "result": "error", "detail": str(exc)[:200]}
            with lock:
                outcomes[name] = outcome
                done = all(n in outcomes for n, _ in pending)
                late = finished.is_set()
                # Only once every action has an outcome (after the timeout, `finish` gave the rest one):
                # before that, the answers still awaited have none.
                result = [outcomes[n] for n in self._clients] if done or late else None
            if late:
                on_done(result)
            elif done:
                finish()

        if not pending:
            finish()
            return
        for name, future in pending:
            future.add_done_callback(lambda f, name=name: answered(name, f))
        self._side.wake()
        timer = threading.Timer(timeout_s, finish)
        timer.daemon = True
        timer.start()
