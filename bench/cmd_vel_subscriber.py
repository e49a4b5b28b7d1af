"""A separate rclpy process that timestamps every /cmd_vel Twist on arrival (CLOCK_MONOTONIC).

Prints "ready" once it sees a publisher, then one line per message: "<t_ns> <linear.x> <angular.z>".
The timestamp is taken first thing in the callback; CLOCK_MONOTONIC is system-wide on Linux, so it
compares directly with the bench process's time.monotonic().
"""

import argparse
import sys
import time

import rclpy
from geometry_msgs.msg import Twist
from rclpy.context import Context
from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--topic", default="/cmd_vel")
    args = parser.parse_args()
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("bench_cmd_vel_subscriber", context=context, start_parameter_services=False,
                             parameter_overrides=[Parameter("start_type_description_service", value=False)])
    out = sys.stdout

    def on_twist(msg: Twist) -> None:
        t = time.monotonic_ns()
        out.write(f"{t} {msg.linear.x!r} {msg.angular.z!r}\n")
        out.flush()

    # A lean node (no parameter services, no QoS-event handlers), like the app's own: the bench
    # measures the server, not this subscriber's executor re-adding waitables on every spin.
    sub = node.create_subscription(Twist, args.topic, on_twist,
                                   QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE),
                                   event_callbacks=SubscriptionEventCallbacks(use_default_callbacks=False))
    deadline = time.monotonic() + 20
    while sub.get_publisher_count() == 0 and time.monotonic() < deadline:
        time.sleep(0.01)
    print("ready", flush=True)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        context.try_shutdown()


if __name__ == "__main__":
    main()
