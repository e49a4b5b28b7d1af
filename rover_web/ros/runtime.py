"""RosRuntime: one private rclpy Context, one Node, one MultiThreadedExecutor on a daemon thread.

Request threads never spin: they publish directly (rclpy publishers are thread-safe) or hand work
to the executor with `run_on_executor`. Subscription callbacks are wrapped so that an exception in
feature code is logged and counted instead of killing the executor, and every subscription feeds
a TopicStats for /api/status.
"""

from __future__ import annotations

import logging
import threading
import time
from typing import Any, Callable

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import get_rmw_implementation_identifier

from ..topic_stats import TopicStats
from . import qos as qos_profiles
from .typesupport import message_class, type_name

log = logging.getLogger(__name__)


class RosRuntime:
    def __init__(self, node_name: str, domain_id: int | None = None, executor_threads: int = 4):
        self.context = Context()
        # rclpy must not install its own SIGINT handler: the process decides how to stop (robot first).
        rclpy.init(context=self.context, domain_id=domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        try:
            self.node = rclpy.create_node(node_name, context=self.context)
        except Exception:
            self.context.try_shutdown()
            raise
        self.executor = MultiThreadedExecutor(num_threads=executor_threads, context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name="ros-executor", daemon=True)
        self._stats: dict[str, TopicStats] = {}
        self._stop_hooks: list[Callable[[], None]] = []
        self._stop_lock = threading.Lock()
        self._stopped = False
        self.callback_errors = 0
        self.started_monotonic = time.monotonic()

    # --- lifecycle ---

    def start(self) -> None:
        self._thread.start()

    def _spin(self) -> None:
        try:
            self.executor.spin()
        except ExternalShutdownException:
            pass
        except Exception:  # pragma: no cover - logged so a dying executor is never silent
            log.exception("ROS executor stopped with an error")

    @property
    def running(self) -> bool:
        return self._thread.is_alive() and not self._stopped

    def on_stop(self, hook: Callable[[], None]) -> None:
        """Run `hook` first when stopping (e.g. publish a zero Twist), in registration order."""
        self._stop_hooks.append(hook)

    def stop(self, timeout_s: float = 2.0) -> None:
        """Ordered shutdown: stop hooks (motion to zero), executor, thread join, node, context."""
        with self._stop_lock:
            if self._stopped:
                return
            self._stopped = True
        for hook in self._stop_hooks:
            try:
                hook()
            except Exception:
                log.exception("stop hook %r failed", hook)
        try:
            self.executor.shutdown(timeout_sec=timeout_s)
        except Exception:
            log.exception("executor shutdown failed")
        if self._thread.ident is not None:  # a feature's init_app can fail before start()
            self._thread.join(timeout_s)
        try:
            self.node.destroy_node()
        finally:
            self.context.try_shutdown()

    # --- graph ---

    @property
    def node_name(self) -> str:
        return self.node.get_fully_qualified_name()

    @property
    def domain_id(self) -> int:
        return self.context.get_domain_id()

    @property
    def middleware(self) -> str:
        return get_rmw_implementation_identifier()

    # --- publish and subscribe ---

    def publisher(self, msg_type: str | type, topic: str, qos: str | int = "default"):
        cls = message_class(msg_type) if isinstance(msg_type, str) else msg_type
        return self.node.create_publisher(cls, topic, self._qos(qos))

    def subscribe(self, msg_type: str | type, topic: str, callback: Callable[[Any], None],
                  qos: str | int = "default", *, track: bool = True):
        """Subscribe with an exception-safe callback; `track` adds the topic to /api/status."""
        cls = message_class(msg_type) if isinstance(msg_type, str) else msg_type
        stats = None
        if track:
            stats = self._stats.setdefault(topic, TopicStats(topic, type_name(cls)))

        def guarded(msg: Any) -> None:
            if stats is not None:
                stats.record()
            try:
                callback(msg)
            except Exception:
                self.callback_errors += 1
                log.exception("callback for %s failed", topic)

        return self.node.create_subscription(cls, topic, guarded, self._qos(qos))

    def destroy(self, entity) -> None:
        """Destroy a publisher or subscription made through this runtime."""
        if hasattr(entity, "topic_name") and entity in self.node.subscriptions:
            self.node.destroy_subscription(entity)
        else:
            self.node.destroy_publisher(entity)

    def run_on_executor(self, fn: Callable[[], Any], timeout_s: float = 2.0) -> Any:
        """Run fn on the executor and wait for its result; TimeoutError if it does not finish."""
        task = self.executor.create_task(fn)
        done = threading.Event()
        task.add_done_callback(lambda _t: done.set())
        self.executor.wake()
        if not done.wait(timeout_s):
            task.cancel()
            raise TimeoutError(f"executor did not run the task within {timeout_s} s")
        return task.result()

    def now_msg(self):
        """The node clock's current time as builtin_interfaces/Time, for stamping headers."""
        return self.node.get_clock().now().to_msg()

    def topic_stats(self, stale_after_s: float) -> list[dict]:
        now = time.monotonic()
        return [s.snapshot(stale_after_s, now) for s in sorted(self._stats.values(), key=lambda s: s.topic)]

    @staticmethod
    def _qos(qos: str | int):
        if isinstance(qos, int):
            return qos_profiles.profile("default", depth=qos)
        if isinstance(qos, str):
            return qos_profiles.profile(qos)
        return qos
