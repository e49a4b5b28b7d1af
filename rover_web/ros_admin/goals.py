"""Goals sent from this app: their latest feedback, status and result, for the event streams. Pure Python.

Feedback is conflated (a stream that falls behind gets the newest), status and result are kept;
finished goals are forgotten past KEEP_FINISHED so the book stays small.
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from typing import Any

KEEP_FINISHED = 50
FINAL = frozenset({"succeeded", "canceled", "aborted", "unknown"})


class Goal:
    def __init__(self, goal_id: str, action: str, type_name: str, handle: Any, by: str):
        self.goal_id, self.action, self.type_name, self.handle, self.by = goal_id, action, type_name, handle, by
        self.started = time.time()
        self.status = "accepted"
        self.feedback: dict | None = None
        self.result: dict | None = None
        self.seq = 0  # +1 per change; streams wait for a newer one
        self.feedback_seq = 0
        self._cond = threading.Condition()

    @property
    def done(self) -> bool:
        return self.result is not None

    def _changed(self) -> None:
        self.seq += 1
        self._cond.notify_all()

    def on_feedback(self, feedback: dict) -> None:
        with self._cond:
            if self.done:
                return
            self.feedback = feedback
            self.feedback_seq = self.seq + 1
            if self.status == "accepted":
                self.status = "executing"
            self._changed()

    def on_status(self, status: str) -> None:
        with self._cond:
            if not self.done and status != self.status:
                self.status = status
                self._changed()

    def on_result(self, status: str, result: dict) -> None:
        with self._cond:
            self.status = status if status in FINAL else "unknown"
            self.result = result
            self._changed()

    def wait_newer(self, seq: int, timeout_s: float) -> int:
        with self._cond:
            if self.seq <= seq:
                self._cond.wait(timeout_s)
            return self.seq

    def snapshot(self) -> dict:
        with self._cond:
            return {"goal_id": self.goal_id, "action": self.action, "type": self.type_name, "by": self.by,
                    "started": self.started, "status": self.status, "feedback": self.feedback,
                    "result": self.result, "seq": self.seq, "feedback_seq": self.feedback_seq}


class GoalBook:
    def __init__(self, keep_finished: int = KEEP_FINISHED):
        self._goals: OrderedDict[str, Goal] = OrderedDict()
        self._keep = keep_finished
        self._lock = threading.Lock()

    def add(self, goal: Goal) -> None:
        with self._lock:
            self._goals[goal.goal_id] = goal
            finished = [g for g in self._goals.values() if g.done]
            for old in finished[:max(0, len(finished) - self._keep)]:
                del self._goals[old.goal_id]

    def get(self, goal_id: str) -> Goal | None:
        with self._lock:
            return self._goals.get(goal_id)

    def all(self) -> list[Goal]:
        with self._lock:
            return list(self._goals.values())

    def running(self) -> list[Goal]:
        return [g for g in self.all() if not g.done]
