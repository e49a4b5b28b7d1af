"""A small node of rover_web's own, beside the main one, spun by its own executor thread.

Clients that wait on answers (the e-stop's CancelGoal clients, the ROS page's service, parameter
and action clients) live here, not on the main node: their waitables would otherwise sit in the
main executor's wait set, rebuilt on every message the GUI takes (BENCHMARKS.md, fourth session).
"""

from __future__ import annotations

import threading

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.parameter import Parameter


class SideNode:
    def __init__(self, runtime, suffix: str, *, namespace: str = ""):
        context = runtime.context
        self.node = rclpy.create_node(
            f"{runtime.node.get_name()}_{suffix}", namespace=namespace or runtime.node.get_namespace(),
            context=context, start_parameter_services=False,
            parameter_overrides=[Parameter("start_type_description_service", value=False)])
        self._executor = SingleThreadedExecutor(context=context)
        self._executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin, name=f"ros-{suffix}-executor", daemon=True)
        self._thread.start()
        runtime.on_stop(self.close)  # before the main node and the context go

    def _spin(self) -> None:
        try:
            self._executor.spin()
        except ExternalShutdownException:
            pass

    def wake(self) -> None:
        """After creating a task or a request from another thread: the executor takes it now."""
        self._executor.wake()

    def close(self) -> None:
        self._executor.shutdown(timeout_sec=1.0)
        self._thread.join(1.0)
        self.node.destroy_node()
