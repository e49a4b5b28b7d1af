"""Spin simulator nodes until SIGINT or SIGTERM, then stop them in order."""

from __future__ import annotations

import argparse
import signal
import sys
import threading
from collections.abc import Callable

import rclpy
from rclpy.context import Context
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.signals import SignalHandlerOptions


def run_part(part, argv: list[str] | None = None) -> None:
    """`python -m rover_web.sim.<part>`: one simulator part alone, with its own options."""
    module = part.__spec__.name if part.__spec__ else part.__name__  # "__main__" under python -m
    parser = argparse.ArgumentParser(prog=f"python -m {module}", description=part.__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    part.add_arguments(parser)
    args = parser.parse_args(argv)
    run_nodes(lambda context: [part.from_arguments(args, context)])


def run_nodes(make_nodes: Callable[[Context], list]) -> None:
    context = Context()
    rclpy.init(context=context, signal_handler_options=SignalHandlerOptions.NO)
    nodes = make_nodes(context)
    # Single-threaded for the same reason as the app (rover_web/ros/runtime.py): rclpy's
    # MultiThreadedExecutor busy-spins; measured here it held the 30 Hz camera to 27.6 Hz.
    executor = SingleThreadedExecutor(context=context)
    for node in nodes:
        executor.add_node(node)
    stop = threading.Event()

    def request_stop(signum, frame):
        stop.set()
        executor.wake()

    signal.signal(signal.SIGINT, request_stop)
    signal.signal(signal.SIGTERM, request_stop)
    # Namespaced nodes by their full names: several robots run nodes of the same name.
    names = ", ".join(n.get_name() if n.get_namespace() == "/" else n.get_fully_qualified_name() for n in nodes)
    print(f"simulator running: {names} (domain {context.get_domain_id()}); Ctrl-C stops it", flush=True)
    spinner = threading.Thread(target=_spin, args=(executor, stop), daemon=True)
    spinner.start()
    stop.wait()  # a signal, or the spinner ending on its own; signal handlers still run while waiting
    # On a loaded machine a callback (the camera encoding a frame) can outlast shutdown's own
    # timeout: wait for the spinner before the nodes go, or spin() would meet destroyed handles.
    executor.shutdown(timeout_sec=2.0)
    spinner.join(10.0)
    for node in nodes:
        node.destroy_node()
    context.try_shutdown()
    print("simulator stopped", flush=True)
    sys.stdout.flush()


def _spin(executor, stop: threading.Event) -> None:
    try:
        executor.spin()
    except ExternalShutdownException:
        pass
    except Exception:
        if not stop.is_set():  # an error while running is shown; one from handles torn down
            raise              # under a stopping spinner is the shutdown itself
    finally:
        stop.set()
