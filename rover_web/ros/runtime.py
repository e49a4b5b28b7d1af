"""RosRuntime: one private rclpy Context, one Node, one executor on a daemon thread.

Request threads never spin: they publish directly (rclpy publishers are thread-safe) or hand work
to the executor with `run_on_executor`. Subscription callbacks are wrapped so that an exception in
feature code is logged and counted instead of killing the executor, and every subscription feeds
a TopicStats for /api/status.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any

import rclpy
from rclpy.context import Context
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.signals import SignalHandlerOptions
from rclpy.utilities import get_rmw_implementation_identifier

from . import qos as qos_profiles
from .raw_taker import RawTaker
from .topic_stats import TopicStats
from .typesupport import message_class, type_name

log = logging.getLogger(__name__)


class RosRuntime:
    def __init__(self, node_name: str, domain_id: int | None = None):
        self.context = Context()
        # rclpy must not install its own SIGINT handler: the process decides how to stop (robot first).
        rclpy.init(context=self.context, domain_id=domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        try:
            # No parameter or type-description services: the GUI has no parameters to serve, and
            # every extra waitable is rebuilt into the executor's wait set on each spin.
            self.node = rclpy.create_node(
                node_name, context=self.context, start_parameter_services=False,
                parameter_overrides=[Parameter("start_type_description_service", value=False)])
        except Exception:
            self.context.try_shutdown()
            raise
        # One executor thread, SingleThreadedExecutor. rclpy 7.1.6's MultiThreadedExecutor busy-spins
        # while a mutually exclusive callback is in flight: measured with 100 Hz odometry it took 53%
        # of a core and lost 37% of the messages, against 6.7% and none lost here (BENCHMARKS.md).
        # Callbacks only update domain objects and the EventHub; slow work (JPEG encoding, map
        # rendering) runs on worker threads, so nothing needs a second executor thread.
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name="ros-executor", daemon=True)
        self._stats: dict[str, TopicStats] = {}
        self._shared: dict[tuple, list[Callable[[Any], None]]] = {}
        self._taker = None  # RawTaker for the shared raw subscriptions, made with the first of them
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
        if self._thread.ident is not None:  # a feature's init_app may fail before start()
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

    # No default QoS-event handlers on our publishers and subscriptions: rclpy re-adds each one to
    # the wait set on every spin in Python, and with ~30 of them that was a third of the executor's
    # time (100 Hz to 10 SSE clients: 16% of a core with them, 10% without). The cost is rclpy's
    # "incompatible QoS" log warning; a topic with a mismatched QoS still shows as never heard
    # in /api/status.
    def publisher(self, msg_type: str | type, topic: str, qos: str | int = "default"):
        cls = message_class(msg_type) if isinstance(msg_type, str) else msg_type
        return self.node.create_publisher(cls, topic, self._qos(qos),
                                          event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))

    def subscribe(self, msg_type: str | type, topic: str, callback: Callable[[Any], None],
                  qos: str | int = "default", *, track: bool = True, raw: bool = False, share: bool = False,
                  taker: bool = True):
        """Subscribe with an exception-safe callback; `track` adds the topic to /api/status.

        `raw` hands the callback the serialized message (bytes) instead of deserializing it, for
        code that measures bandwidth or decodes only some messages. `share`: features that read the
        same topic (telemetry and the GPS heading both read /odom) get one subscription between
        them, with the same type, QoS and rawness, so each message is taken once, not once each;
        such a subscription is never destroyed. A shared raw subscription (the high-rate topics
        the app reads at known offsets) is taken by a thread of its own, not the executor
        (raw_taker.py: the executor's per-message Python was most of what /odom cost); its
        callbacks must be thread-safe, and it returns None. `taker=False` keeps a shared raw subscription
        on the executor: for a topic whose callbacks do heavy work now and then (a MarkerArray's
        conversion), which on the taker thread would hold back /tf and /odom behind it.
        """
        cls = message_class(msg_type) if isinstance(msg_type, str) else msg_type
        if share:
            key = (topic, type_name(cls), str(qos), raw)
            callbacks = self._shared.get(key)
            if callbacks is not None:
                callbacks.append(callback)
                return None
            callbacks = self._shared[key] = [callback]

            def callback(msg: Any, callbacks=callbacks) -> None:
                for each in callbacks:
                    try:
                        each(msg)
                    except Exception:
                        self.callback_errors += 1
                        log.exception("callback for %s failed", topic)
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

        if share and raw and taker:
            if self._taker is None:
                self._taker = RawTaker(self, "shared", node=self.node)
            self._taker.subscribe(cls, topic, lambda data, _received_ns: guarded(data), self._qos(qos))
            return None
        return self.node.create_subscription(
            cls, topic, guarded, self._qos(qos), raw=raw,
            event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))

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

    def tracks(self, topic: str) -> bool:
        """Whether a subscription already counts `topic`'s messages for /api/status (a second would double its rate)."""
        return topic in self._stats

    def topic_stats(self, stale_after_s: float, under: str = "") -> list[dict]:
        """Every tracked topic, or those under the namespace `under` (one robot's, of several)."""
        now = time.monotonic()
        prefix = under.rstrip("/") + "/"
        return [s.snapshot(stale_after_s, now) for s in sorted(self._stats.values(), key=lambda s: s.topic)
                if s.topic.startswith(prefix)]

    @staticmethod
    def _qos(qos: str | int):
        if isinstance(qos, int):
            return qos_profiles.profile("default", depth=qos)
        if isinstance(qos, str):
            return qos_profiles.profile(qos)
        return qos
