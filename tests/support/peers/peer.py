"""A real rclpy node in its own process, driven by the tests over stdin/stdout (JSON lines).

Commands (stdin):  {"op": "sub"|"pub", "topic", "type", "qos"}  {"op": "send", "topic", "msg"}
                   ("qos": a profile name, or an int: reliable, volatile, keep-last of that depth)
                   {"op": "wait_match", "topic", "count", "timeout"}  {"op": "quit"}
                   {"op": "log", "level": "debug"|"info"|"warning"|"error"|"fatal", "text", "times"}
                   (through the node's own logger, so the lines reach /rosout as any node's do)
                   {"op": "graph", "count": [topics]} -> ack with nodes, topics, pub/sub counts
Events (stdout):   {"event": "ready"}  {"event": "ack", "op"}  {"event": "error", "message"}
                   {"event": "msg", "topic", "t": <CLOCK_MONOTONIC seconds>, "sent": <s>, "msg": {...}}
CLOCK_MONOTONIC is system-wide on Linux, so "t" compares directly with the test's time.monotonic().
"sent" is the middleware's source timestamp (wall clock, s): when the publisher wrote it, which a
loaded machine does not move the way it moves when this process got to take it.
"""

import json
import sys
import threading
import time

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.logging import LoggingSeverity
from rclpy.signals import SignalHandlerOptions

from rover_web.ros import qos
from rover_web.ros.convert import dict_to_message, message_to_dict
from rover_web.ros.typesupport import message_class

out_lock = threading.Lock()

# rclpy remembers each logging call site's severity and refuses another one there, so one call
# site per level.
LOG = {
    "debug": lambda logger, text: logger.debug(text),
    "info": lambda logger, text: logger.info(text),
    "warning": lambda logger, text: logger.warning(text),
    "error": lambda logger, text: logger.error(text),
    "fatal": lambda logger, text: logger.fatal(text),
}


def profile(name):
    return qos.profile("default", depth=name) if isinstance(name, int) else qos.profile(name)


def emit(**event):
    line = json.dumps(event)
    with out_lock:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()


def _callback(emit, topic: str, max_items: int):
    # Two parameters and no defaults: rclpy passes the message info only to a callback that way.
    def callback(msg, info):
        emit(event="msg", topic=topic, t=time.monotonic(), sent=info["source_timestamp"] / 1e9,
             msg=message_to_dict(msg, max_items=max_items))
    return callback


def main():
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(sys.argv[1] if len(sys.argv) > 1 else "test_peer", context=context)
    node.get_logger().set_level(LoggingSeverity.DEBUG)
    # Single-threaded: the multi-threaded executor busy-spins and delivers late under load.
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    pubs, subs = {}, {}

    def spin():
        try:
            executor.spin()
        except ExternalShutdownException:
            pass

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    emit(event="ready")
    for line in sys.stdin:
        try:
            cmd = json.loads(line)
            op = cmd["op"]
            if op == "quit":
                break
            if op == "sub":
                topic = cmd["topic"]

                max_items = cmd.get("max_items", 64)

                subs[topic] = node.create_subscription(message_class(cmd["type"]), topic,
                                                       _callback(emit, topic, max_items),
                                                       profile(cmd.get("qos", "default")))
            elif op == "pub":
                pubs[cmd["topic"]] = (cmd["type"], node.create_publisher(
                    message_class(cmd["type"]), cmd["topic"], profile(cmd.get("qos", "default"))))
            elif op == "send":
                type_name, pub = pubs[cmd["topic"]]
                pub.publish(dict_to_message(type_name, cmd.get("msg", {})))
            elif op == "log":
                write = LOG[cmd.get("level", "info")]
                for _ in range(cmd.get("times", 1)):
                    write(node.get_logger(), cmd["text"])
            elif op == "unsub":
                node.destroy_subscription(subs.pop(cmd["topic"]))
            elif op == "wait_match":
                topic, count = cmd["topic"], cmd.get("count", 1)
                deadline = time.monotonic() + cmd.get("timeout", 10)
                while time.monotonic() < deadline:
                    if topic in pubs and pubs[topic][1].get_subscription_count() >= count:
                        break
                    if topic in subs and subs[topic].get_publisher_count() >= count:
                        break
                    time.sleep(0.01)
                else:
                    emit(event="error", op=op, message=f"no match on {topic} within timeout")
                    continue
            if op == "graph":
                emit(event="ack", op=op, id=cmd.get("id"),
                     nodes=[ns.rstrip("/") + "/" + n for n, ns in node.get_node_names_and_namespaces()],
                     topics={name: types for name, types in node.get_topic_names_and_types()},
                     publishers={t: node.count_publishers(t) for t in cmd.get("count", [])},
                     subscribers={t: node.count_subscribers(t) for t in cmd.get("count", [])})
                continue
            emit(event="ack", op=op, id=cmd.get("id"))
        except Exception as exc:  # report and keep serving: the test decides what an error means
            emit(event="error", op=line[:80], message=repr(exc))
    executor.shutdown(timeout_sec=1.0)
    spinner.join(2)
    node.destroy_node()
    context.try_shutdown()


if __name__ == "__main__":
    main()
