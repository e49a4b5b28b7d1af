"""Idle RSS: the app with no viewer, against the floor of what it is built on.

    .venv/bin/python bench/memory.py [--starts 3] [--settle-s 4]

Each start is `flask --app rover_web run --no-reload` in its own process (common.Server), measured
`--settle-s` after /api/status first answers, with nobody connected. Two configurations: the
defaults (the bundled floorplans, whose images and keep-out areas are checked at start with Pillow
and shapely) and a robot with no floorplans (ROVER_WEB_MAPS_FILE empty). The floor is a process
that does only what any rclpy + Flask server must: one rclpy node spinning on an executor thread,
and Flask with the extensions rover_web uses imported. The libraries column says which of the
heavy optional ones the idle app has mapped (read from /proc/<pid>/maps), i.e. loaded at start.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

import psutil
from common import Server, machine, ros_env, stop_process

# Issue 32: idle RSS held to the floor (an rclpy node spinning, Flask imported) plus this much.
FLOOR_ALLOWANCE_MB = 20.0

FLOOR = """
import os, signal, threading, time
signal.signal(signal.SIGTERM, lambda *_: os._exit(0))
import rclpy
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from geometry_msgs.msg import Twist
import flask, flask_login, flask_sock, jinja2, orjson, werkzeug, yaml, sqlite3
rclpy.init()
node = Node("floor")
node.create_publisher(Twist, "/cmd_vel", 10)
executor = SingleThreadedExecutor()
executor.add_node(node)
threading.Thread(target=executor.spin, daemon=True).start()
print("ready", flush=True)
time.sleep(3600)
"""

# A shared object's path fragment -> the library it stands for.
LIBRARIES = {"shapely": "shapely", "PIL/_imaging": "Pillow", "lxml/": "lxml (URDF)", "_argon2_cffi_bindings": "argon2",
             "lz4/": "lz4 (mcap)", "zstandard": "zstandard (mcap)", "aiortc": "aiortc", "av/": "av",
             "jsonschema": "jsonschema", "_asyncio": "asyncio"}


def loaded_libraries(pid: int) -> list[str]:
    with open(f"/proc/{pid}/maps") as f:
        maps = f.read()
    return sorted({name for fragment, name in LIBRARIES.items() if fragment in maps})


def app_rss(env: dict, settle_s: float) -> tuple[float, list[str]]:
    server = Server(env)
    try:
        time.sleep(settle_s)
        return server.rss_mb(), loaded_libraries(server.proc.pid)
    finally:
        server.stop()


def floor_rss(env: dict, settle_s: float) -> float:
    proc = subprocess.Popen([sys.executable, "-c", FLOOR], env=env, stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "ready"
        time.sleep(settle_s)
        return psutil.Process(proc.pid).memory_info().rss / 1e6
    finally:
        stop_process(proc)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--starts", type=int, default=3)
    parser.add_argument("--settle-s", type=float, default=4.0)
    args = parser.parse_args()
    print(machine(), flush=True)
    rows = [("rover_web, defaults", {}), ("rover_web, no floorplans", {"ROVER_WEB_MAPS_FILE": ""})]
    medians = {}
    for label, extra in rows:
        runs = [app_rss(ros_env(**extra), args.settle_s) for _ in range(args.starts)]
        rss = [r for r, _ in runs]
        medians[label] = statistics.median(rss)
        print(f"{label:28s} RSS median {statistics.median(rss):6.1f} MB  (runs {', '.join(f'{r:.1f}' for r in rss)})"
              f"  optional libraries loaded: {', '.join(runs[-1][1]) or 'none'}", flush=True)
    floors = [floor_rss(ros_env(), args.settle_s) for _ in range(args.starts)]
    print(f"{'floor: rclpy node + Flask':28s} RSS median {statistics.median(floors):6.1f} MB  "
          f"(runs {', '.join(f'{r:.1f}' for r in floors)})", flush=True)
    # Issue 32's target, as the stack allows it: what rover_web adds over an rclpy node with Flask.
    floor = statistics.median(floors)
    for label, rss in medians.items():
        print(f"target {label}: floor + {rss - floor:.1f} MB (<= floor + {FLOOR_ALLOWANCE_MB:.0f} MB: "
              f"{'met' if rss - floor <= FLOOR_ALLOWANCE_MB else 'NOT met'})", flush=True)
    print(json.dumps({"floor_mb": round(floor, 1), **{k: round(v, 1) for k, v in medians.items()},
                      "allowance_mb": FLOOR_ALLOWANCE_MB}))


if __name__ == "__main__":
    main()
