"""RawTaker: raw subscriptions on a node of their own, taken by one thread without an executor.

For recordings (rover_web/recording), which take every message of many topics as bytes and do
nothing with it but append it to a queue. On an rclpy executor each message cost a wake of the
executor thread that rebuilt its whole wait set in Python (every subscription of the app, ~35,
each entered as a context manager) to run one callback: recording 20 topics took 9 % of a core
in the executor thread alone (bench/recording_profile.py, BENCHMARKS.md). Here one thread waits on
these subscriptions only, with a wait set kept while they do not change, and takes every message
waiting on a ready subscription in one go; rclpy's own `wait_for_message` uses the same calls
(`_rclpy.WaitSet`, `take_message`) for one subscription.

The subscriptions live on a node in no executor, so nothing else ever takes their messages; they
are created from any thread and destroyed by the taker thread only (between two waits), so a
handle is never freed while a wait uses it.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import rclpy
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.parameter import Parameter

from .typesupport import message_class

log = logging.getLogger(__name__)

WAIT_NS = 1_000_000_000  # the thread looks at `closed` at least this often
MAX_TAKE = 100  # messages taken from one subscription per wake, so none can starve the others


class RawTaker:
    def __init__(self, runtime, suffix: str, *, namespace: str = ""):
        self._context = runtime.context
        self.node = rclpy.create_node(
            f"{runtime.node.get_name()}_{suffix}", namespace=namespace or runtime.node.get_namespace(),
            context=self._context, start_parameter_services=False,
            parameter_overrides=[Parameter("start_type_description_service", value=False)])
        with self._context.handle:
            self._wake = _rclpy.GuardCondition(self._context.handle)
        self._lock = threading.Lock()
        self._taken: dict[int, tuple[object, Callable[[bytes, int], None]]] = {}  # id(subscription) -> it, callback
        self._retired: list[tuple[object, threading.Event]] = []
        self._changed = True
        self._closed = False
        self.callback_errors = 0
        self._thread = threading.Thread(target=self._run, name=f"ros-{suffix}-taker", daemon=True)
        self._thread.start()
        runtime.on_stop(self.close)  # before the context goes

    def subscribe(self, msg_type: str, topic: str, callback: Callable[[bytes, int], None], qos):
        """callback(data, received_ns) on the taker thread for each message of `topic`: its bytes as
        they came, and when the middleware received it (ns since the epoch; 0 if it does not say).
        Messages taken together in one wake keep their own reception times."""
        subscription = self.node.create_subscription(
            message_class(msg_type), topic, _never_called, qos, raw=True,
            event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))
        with self._lock:
            self._taken[id(subscription)] = (subscription, callback)
            self._changed = True
        self._wake.trigger_guard_condition()
        return subscription

    def unsubscribe(self, subscription, timeout_s: float = 2.0) -> None:
        """No more callbacks for it once this returns (or after timeout_s, if the thread is stuck)."""
        done = threading.Event()
        with self._lock:
            if self._taken.pop(id(subscription), None) is None:
                return
            self._retired.append((subscription, done))
            self._changed = True
        if threading.current_thread() is self._thread:
            return  # from a callback: destroyed after this wake
        self._wake.trigger_guard_condition()
        done.wait(timeout_s)

    def close(self) -> None:
        self._closed = True
        self._wake.trigger_guard_condition()
        self._thread.join(2.0)
        if not self._thread.is_alive():
            self.node.destroy_node()
            self._wake.destroy_when_not_in_use()

    # --- the taker thread ---

    def _run(self) -> None:
        wait_set = None
        taken: list[tuple[object, Callable]] = []
        try:
            while not self._closed:
                if self._changed:
                    wait_set, taken = self._rebuild()
                wait_set.clear_entities()
                for subscription, _ in taken:
                    wait_set.add_subscription(subscription.handle)
                wait_set.add_guard_condition(self._wake)
                wait_set.wait(WAIT_NS)
                if self._closed or not self._context.ok():
                    break
                ready = wait_set.get_ready_entities("subscription")
                if ready:
                    self._take(taken, ready)
        except Exception:  # pragma: no cover - logged so a dying taker is never silent
            log.exception("raw taker %s stopped with an error", self.node.get_name())
        finally:
            self._release()

    def _rebuild(self):
        with self._lock:
            self._changed = False
            retired, self._retired = self._retired, []
            taken = list(self._taken.values())
        for subscription, done in retired:  # in no wait now: this thread is the only one waiting
            self.node.destroy_subscription(subscription)
            done.set()
        wait_set = _rclpy.WaitSet(len(taken), 1, 0, 0, 0, 0, self._context.handle)
        return wait_set, taken

    def _take(self, taken, ready) -> None:
        for subscription, callback in taken:
            handle = subscription.handle
            if handle.pointer not in ready:
                continue
            msg_type = subscription.msg_type
            for _ in range(MAX_TAKE):
                message = handle.take_message(msg_type, True)
                if message is None:
                    break
                try:
                    callback(message[0], message[1].get("received_timestamp") or 0)
                except Exception:
                    self.callback_errors += 1
                    log.exception("raw callback for %s failed", subscription.topic_name)

    def _release(self) -> None:
        with self._lock:
            retired, self._retired = self._retired, []
        for _subscription, done in retired:
            done.set()


def _never_called(_message) -> None:  # the node is in no executor
    pass
