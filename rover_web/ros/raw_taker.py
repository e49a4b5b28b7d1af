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

Given the app's own node (`node=`), a taker makes its subscriptions on that node's handle without
registering them with the node, so the executor never waits on them and the graph shows no second
node: the runtime takes its high-rate shared topics (/odom at 50-100 Hz) this way
(RosRuntime.subscribe(share=True, raw=True)), off the executor's per-wake Python.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable

import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.parameter import Parameter
from rclpy.type_support import check_is_valid_msg_type

from .typesupport import message_class

log = logging.getLogger(__name__)

WAIT_NS = 1_000_000_000  # the thread looks at `closed` at least this often
MAX_TAKE = 100  # messages taken from one subscription per wake, so none can starve the others


class _Detached:
    """A subscription on a node's handle that the node does not know, so no executor waits on it."""

    def __init__(self, node, msg_type, topic: str, qos):
        check_is_valid_msg_type(msg_type)  # imports the type support
        with node.handle:
            self.handle = _rclpy.Subscription(node.handle, msg_type, topic, qos.get_c_qos_profile())
        self.msg_type = msg_type
        self.topic_name = self.handle.get_topic_name()

    def destroy(self) -> None:
        self.handle.destroy_when_not_in_use()


class RawTaker:
    def __init__(self, runtime, suffix: str, *, namespace: str = "", node=None):
        """A node of its own, named after the runtime's with `suffix`; or, given `node`, subscriptions
        on that node that its executor never sees."""
        self._context = runtime.context
        self._own_node = node is None
        self.node = node if node is not None else rclpy.create_node(
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

    def subscribe(self, msg_type: str | type, topic: str, callback: Callable[[bytes, int], None], qos):
        """callback(data, received_ns) on the taker thread for each message of `topic`: its bytes as
        they came, and when the middleware received it (ns since the epoch; 0 if it does not say).
        Messages taken together in one wake keep their own reception times."""
        cls = message_class(msg_type) if isinstance(msg_type, str) else msg_type
        # Detached on either node: the taker alone owns and destroys it (its own node is in no
        # executor anyway, and the runtime's must not see it).
        subscription = _Detached(self.node, cls, topic, qos)
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
            with self._lock:
                left, self._taken = list(self._taken.values()), {}
            for subscription, _ in left:
                subscription.destroy()
            if self._own_node:
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
            subscription.destroy()
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
