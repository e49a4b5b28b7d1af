"""A node with parameters of every type and std_srvs services, in its own process.

    python admin_peer.py /peer_ns param_peer

Parameters: flag (bool), count (integer), gain (double), label (string), ids (integer array),
weights (double array), names (string array), blob (byte array), flags (bool array), serial
(read-only string), speed (double, 0.0 to 2.0), level (integer, 0 to 10 step 2), guarded (string
that the node itself refuses to set to "forbidden"), ntrip_password (a string whose name says secret).
Services (in the node's namespace): set_enabled (SetBool), trigger (Trigger), reset (Empty),
silent (Trigger that never answers).
stdout: {"event": "ready"}, {"event": "called", "service", "request"}; stdin: "quit".
"""

import json
import sys
import threading

import rclpy
from rcl_interfaces.msg import FloatingPointRange, IntegerRange, ParameterDescriptor, SetParametersResult
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from std_srvs.srv import Empty, SetBool, Trigger

quitting = threading.Event()


def emit(**event) -> None:
    print(json.dumps(event), flush=True)


def main() -> None:
    namespace, name = sys.argv[1], sys.argv[2]
    rclpy.init()
    node = rclpy.create_node(name, namespace=namespace)
    node.declare_parameter("flag", True, ParameterDescriptor(description="a switch"))
    node.declare_parameter("count", 3)
    node.declare_parameter("gain", 0.5)
    node.declare_parameter("label", "hello")
    node.declare_parameter("ids", [1, 2, 3])
    node.declare_parameter("weights", [0.5, 1.5])
    node.declare_parameter("names", ["a", "b"])
    node.declare_parameter("flags", [True, False])
    node.declare_parameter("serial", "SN-1", ParameterDescriptor(read_only=True))
    node.declare_parameter("speed", 1.0, ParameterDescriptor(
        floating_point_range=[FloatingPointRange(from_value=0.0, to_value=2.0, step=0.0)]))
    node.declare_parameter("level", 4, ParameterDescriptor(
        integer_range=[IntegerRange(from_value=0, to_value=10, step=2)]))
    node.declare_parameter("guarded", "ok")
    node.declare_parameter("ntrip_password", "hunter2")

    def check(params):
        for p in params:
            if p.name == "guarded" and p.value == "forbidden":
                return SetParametersResult(successful=False, reason="guarded may not be forbidden")
        return SetParametersResult(successful=True)

    node.add_on_set_parameters_callback(check)
    state = {"enabled": False}

    def set_enabled(request, response):
        state["enabled"] = request.data
        emit(event="called", service="set_enabled", request={"data": request.data})
        response.success = True
        response.message = f"enabled={request.data}"
        return response

    def trigger(_request, response):
        emit(event="called", service="trigger", request={})
        response.success = True
        response.message = "triggered"
        return response

    def reset(_request, response):
        emit(event="called", service="reset", request={})
        return response

    def silent(_request, response):
        emit(event="called", service="silent", request={})
        quitting.wait(60)  # never answers while the test runs
        return response

    group = ReentrantCallbackGroup()
    node.create_service(SetBool, "set_enabled", set_enabled)
    node.create_service(Trigger, "trigger", trigger)
    node.create_service(Empty, "reset", reset)
    node.create_service(Trigger, "silent", silent, callback_group=group)
    executor = MultiThreadedExecutor(num_threads=3)
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    emit(event="ready")
    for line in sys.stdin:
        if line.strip() == "quit":
            break
    quitting.set()
    executor.shutdown(timeout_sec=2)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
