"""A navigation-like action server in its own process: test_msgs/action/Fibonacci under any name.

    python action_server.py /navigate_to_pose [cancel_delay_s]

Goals of order 1000 and more run until canceled (one step every 50 ms); a smaller order finishes
after that many steps, with the Fibonacci sequence so far as feedback and the whole as result.
Lines on stdout, JSON: {"event": "ready"},
{"event": "accepted", "t": ...}, {"event": "canceled", "t": ...} (t: CLOCK_MONOTONIC seconds).
On stdin, "goal" sends one goal to this very server (through an ActionClient), "quit" ends.
With cancel_delay_s, a cancel request is answered that long after it came (a busy robot's server).
"""

import json
import sys
import threading
import time

import rclpy
from rclpy.action import ActionClient, ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from test_msgs.action import Fibonacci


def emit(**event) -> None:
    print(json.dumps(event), flush=True)


def main() -> None:
    name = sys.argv[1]
    cancel_delay_s = float(sys.argv[2]) if len(sys.argv) > 2 else 0.0
    rclpy.init()
    node = rclpy.create_node("fake_nav_server")
    group = ReentrantCallbackGroup()

    def execute(goal_handle):
        feedback = Fibonacci.Feedback()
        order = goal_handle.request.order
        if order < 1000:
            sequence = [0, 1]
            for _ in range(max(0, order - 1)):
                if goal_handle.is_cancel_requested:
                    goal_handle.canceled()
                    emit(event="canceled", t=time.monotonic())
                    return Fibonacci.Result(sequence=sequence)
                sequence.append(sequence[-1] + sequence[-2])
                feedback.sequence = sequence
                goal_handle.publish_feedback(feedback)
                time.sleep(0.05)
            goal_handle.succeed()
            return Fibonacci.Result(sequence=sequence)
        while rclpy.ok():
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                emit(event="canceled", t=time.monotonic())
                return Fibonacci.Result()
            goal_handle.publish_feedback(feedback)
            time.sleep(0.05)
        return Fibonacci.Result()

    def on_goal(_request):
        emit(event="accepted", t=time.monotonic())
        return GoalResponse.ACCEPT

    def on_cancel(_handle):
        time.sleep(cancel_delay_s)
        return CancelResponse.ACCEPT

    ActionServer(node, Fibonacci, name, execute, goal_callback=on_goal,
                 cancel_callback=on_cancel, callback_group=group)
    client = ActionClient(node, Fibonacci, name, callback_group=group)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    threading.Thread(target=executor.spin, daemon=True).start()
    emit(event="ready")
    for line in sys.stdin:
        command = line.strip()
        if command == "quit":
            break
        if command == "goal":
            client.wait_for_server(timeout_sec=10)
            client.send_goal_async(Fibonacci.Goal(order=1000))
    executor.shutdown(timeout_sec=2)
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == "__main__":
    main()
