"""TF: what taking 1,000 transforms a second (200 frames) costs the server, and how long a lookup
through a 10-frame chain takes.

    .venv/bin/python bench/tf.py [--seconds 20]

1. The app under `flask run` in its own process; its CPU is measured while idle, then while
   bench/tf_publisher.py (another process) sends /tf at 1,000 transforms/s across 200 frames; the
   difference is TF's ingestion (the raw subscription, the CDR reader, the buffer's inserts and
   the 1 Hz tree on the `tf` channel). The transforms the server counted are checked against
   those sent.
2. In this process, a TfBuffer holding the same 200 frames as the server does (10 s of them at
   5 Hz each, every link moving and turning) answers lookups from the chain's end to map: at the
   latest common time and at a stamp between two samples (a slerp and a lerp on each of the 10
   links). p50/p99 over many lookups, wall-clock and on-CPU.

Prints a line per figure, then one JSON line.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

import requests
from common import ROOT, Server, machine, ros_env, stop_process

from rover_web.tf.buffer import TfBuffer

TARGET_CPU_PCT = 5.0
TARGET_P99_US = 50.0


def server_cpu(seconds: float) -> dict:
    env = ros_env()
    server = Server(env)
    try:
        time.sleep(3)  # start-up work done
        c0, t0 = server.cpu_seconds(), time.monotonic()
        time.sleep(seconds)
        idle_pct = (server.cpu_seconds() - c0) / (time.monotonic() - t0) * 100
        before = requests.get(server.url + "/api/tf", timeout=5).json()["counts"]["transforms"]
        pub = subprocess.Popen([sys.executable, str(ROOT / "bench" / "tf_publisher.py"), "--seconds", str(seconds)],
                               cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True)
        try:
            line = pub.stdout.readline()
            if "publishing" not in line:
                raise RuntimeError(f"publisher did not start: {line!r}")
            c0, t0 = server.cpu_seconds(), time.monotonic()
            summary = json.loads(pub.stdout.readline())
            busy_pct = (server.cpu_seconds() - c0) / (time.monotonic() - t0) * 100
        finally:
            stop_process(pub)
        time.sleep(1.0)
        tree = requests.get(server.url + "/api/tf", timeout=5).json()
        received = tree["counts"]["transforms"] - before
        return {"idle_cpu_pct": round(idle_pct, 2), "busy_cpu_pct": round(busy_pct, 2),
                "tf_cpu_pct": round(busy_pct - idle_pct, 2),
                "sent_per_s": round(summary["sent_transforms"] / summary["seconds"], 1),
                "sent": summary["sent_transforms"], "received": received, "frames": len(tree["frames"]) - 1,
                "rss_mb": round(server.rss_mb(), 1)}
    finally:
        server.stop()


def lookups(n: int) -> dict:
    buffer = TfBuffer(10.0)
    pairs = [("map" if i == 1 else f"f{i - 1}", f"f{i}") for i in range(1, 11)]
    pairs += [(f"f{1 + i % 10}", f"leaf{i}") for i in range(190)]
    start = 1_000 * 10**9
    for k in range(50):  # 10 s at 5 Hz, as the server holds them; every link moves and turns
        stamp = start + k * 200_000_000
        yaw = 0.05 + 0.01 * k
        q = (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))
        for parent, child in pairs:
            buffer.set_transform(parent, child, (0.1 + 0.01 * k, 0.2, 0.05), q, stamp, static=False)
    out = {}
    for name, stamp in (("latest", None), ("interpolated", start + 5_100_000_000)):
        wall, cpu = [], []
        for _ in range(n):
            c0, t0 = time.thread_time_ns(), time.perf_counter_ns()
            buffer.lookup("map", "f10", stamp)
            t1, c1 = time.perf_counter_ns(), time.thread_time_ns()
            wall.append(t1 - t0)
            cpu.append(c1 - c0)
        wall.sort()
        cpu.sort()
        # Wall-clock time includes the times the thread was preempted (on a loaded machine, most of
        # the p99); on-CPU time (CLOCK_THREAD_CPUTIME_ID) is the lookup's own work.
        out[name] = {"p50_us": round(wall[len(wall) // 2] / 1000, 2),
                     "p99_us": round(wall[int(len(wall) * 0.99)] / 1000, 2),
                     "mean_us": round(statistics.fmean(wall) / 1000, 2),
                     "cpu_p50_us": round(cpu[len(cpu) // 2] / 1000, 2),
                     "cpu_p99_us": round(cpu[int(len(cpu) * 0.99)] / 1000, 2)}
    return out


def load() -> str:
    one, five, _ = os.getloadavg()
    return f"load average {one:.1f} (1 min), {five:.1f} (5 min) on {os.cpu_count()} cores"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--lookups", type=int, default=50_000)
    args = parser.parse_args()
    look = lookups(args.lookups)
    for name, figures in look.items():
        print(f"lookup map <- f10 (10 links), {name}: p50 {figures['p50_us']} us, p99 {figures['p99_us']} us "
              f"(on-CPU p50 {figures['cpu_p50_us']} us, p99 {figures['cpu_p99_us']} us)")
    cpu = server_cpu(args.seconds)
    print(f"server CPU idle {cpu['idle_cpu_pct']} %, with {cpu['sent_per_s']} transforms/s {cpu['busy_cpu_pct']} %: "
          f"TF ingestion {cpu['tf_cpu_pct']} % of a core; received {cpu['received']} of {cpu['sent']}, "
          f"{cpu['frames']} frames")
    result = {"bench": "tf", "machine": machine(), "load": load(), **cpu, "lookup": look,
              "targets": {"tf_cpu_pct": TARGET_CPU_PCT, "lookup_p99_us": TARGET_P99_US},
              "met": {"cpu": cpu["tf_cpu_pct"] <= TARGET_CPU_PCT,
                      "lookup": max(v["p99_us"] for v in look.values()) <= TARGET_P99_US}}
    print(json.dumps(result))


if __name__ == "__main__":
    main()
