"""POST /waypoints (the seeds' call) at 1 and 8 concurrent clients: throughput, HTTP latency, latency
to the /waypoints topic, server CPU and RSS; then checks every acknowledged waypoint is on the
topic and in the database, and that the topic carried them in the mission's order.

    .venv/bin/python bench/waypoints.py [--requests 3000] [--clients 1 8] [--server gunicorn|flask]

Everything runs on 127.0.0.1: the app (gunicorn with gunicorn.conf.py by default: one worker,
gthread, as the README recommends; or `flask run`), one rclpy subscriber in its own process
(reliable, keep-last 1000, so it never drops a message), and the clients in this process, each a
keep-alive http.client connection. "Latency to the topic" is the subscriber's arrival time minus
the moment the client started the request (CLOCK_MONOTONIC in both processes).
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import shutil
import sqlite3
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

import psutil
import requests
from common import ROOT, Server, machine, percentile, ros_env

sys.path.insert(0, str(ROOT))

FLOAT64_MULTI_ARRAY = "std_msgs/msg/Float64MultiArray"


def post_many(url: str, bodies: list[dict], results: list) -> None:
    host, port = url.removeprefix("http://").split(":")
    conn = http.client.HTTPConnection(host, int(port), timeout=30)
    headers = {"Content-Type": "application/json"}
    for body in bodies:
        data = json.dumps(body)
        t0 = time.monotonic()
        for attempt in (0, 1):
            try:
                conn.request("POST", "/waypoints", data, headers)
                response = conn.getresponse()
                response.read()
                break
            except (http.client.HTTPException, ConnectionError):
                conn.close()  # the server closed an idle keep-alive connection: reconnect once
                if attempt:
                    raise
        results.append((body["lng"], body["lat"], t0, time.monotonic(), response.status))
    conn.close()


def server_cpu_seconds(server: Server) -> float:
    total = 0.0
    for proc in [server.ps, *server.ps.children(recursive=True)]:
        try:
            t = proc.cpu_times()
            total += t.user + t.system
        except psutil.NoSuchProcess:
            pass
    return total


def server_rss_mb(server: Server) -> float:
    return sum(p.memory_info().rss for p in [server.ps, *server.ps.children(recursive=True)]) / 1e6


def run_level(server: Server, peer, db_path: Path, clients: int, total: int, tag: float) -> dict:
    requests.delete(server.url + "/api/waypoints", timeout=10).raise_for_status()
    time.sleep(0.3)
    peer.clear("/waypoints")
    per_client = total // clients
    results: list = []
    lists = [[] for _ in range(clients)]
    threads = []
    for c in range(clients):
        bodies = [{"lng": -82.46 + (c * per_client + i) * 1e-7, "lat": tag} for i in range(per_client)]
        threads.append(threading.Thread(target=post_many, args=(server.url, bodies, lists[c])))
    cpu0 = server_cpu_seconds(server)
    start = time.monotonic()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    wall = time.monotonic() - start
    cpu = server_cpu_seconds(server) - cpu0
    for part in lists:
        results += part
    acked = [r for r in results if 200 <= r[4] < 300]

    deadline = time.monotonic() + 15
    while len(peer.received("/waypoints")) < len(acked) and time.monotonic() < deadline:
        time.sleep(0.05)
    heard = {tuple(m["msg"]["data"]): m["t"] for m in peer.received("/waypoints")}
    topic_latency = [heard[(lng, lat)] - t0 for lng, lat, t0, _, _ in acked if (lng, lat) in heard]
    conn = sqlite3.connect(db_path)
    try:
        stored_in_order = conn.execute("SELECT lng, lat FROM waypoints WHERE lat = ? ORDER BY position",
                                       (tag,)).fetchall()
    finally:
        conn.close()
    stored = set(stored_in_order)
    heard_in_order = [tuple(m["msg"]["data"]) for m in peer.received("/waypoints")]
    return {
        "clients": clients, "sent": len(results), "acked": len(acked), "wall_s": wall,
        "throughput": len(acked) / wall,
        "http_ms": [(t1 - t0) * 1000 for _, _, t0, t1, _ in acked],
        "topic_ms": [x * 1000 for x in topic_latency],
        "missing_topic": sum(1 for lng, lat, *_ in acked if (lng, lat) not in heard),
        "missing_db": sum(1 for lng, lat, *_ in acked if (lng, lat) not in stored),
        "same_order": heard_in_order == stored_in_order,
        "cpu_pct": 100 * cpu / wall, "rss_mb": server_rss_mb(server),
    }


def fmt(ms: list[float]) -> str:
    return f"median {statistics.median(ms):6.2f} ms  p99 {percentile(ms, 99):6.2f} ms" if ms else "n/a"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--requests", type=int, default=3000, help="requests per concurrency level")
    parser.add_argument("--clients", type=int, nargs="*", default=[1, 8])
    parser.add_argument("--server", choices=["gunicorn", "flask"], default="gunicorn")
    args = parser.parse_args()

    work = Path(tempfile.mkdtemp(prefix="rover_web-bench-waypoints-"))
    db_path = work / "bench.sqlite3"
    env = ros_env(ROVER_WEB_DB_PATH=str(db_path), ROVER_WEB_MAX_WAYPOINTS="100000",
                  ROVER_WEB_MAP_TILES=str(work / "no-tiles"))
    os.environ.update({k: env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    from tests.support.rospeer import RosPeer  # after the domain is set: the peer inherits this environment
    from tests.support.waypoint_helpers import warm_up_topic

    server = Server(env, kind=args.server)
    peer = RosPeer("bench_waypoints")
    try:
        peer.subscribe("/waypoints", FLOAT64_MULTI_ARRAY, qos=1000)
        peer.wait_match("/waypoints")
        warm_up_topic(server.url, peer)
        run_level(server, peer, db_path, 8, 400, 1.0)  # warm-up: connections, caches, DDS
        print(f"# waypoints bench on {machine()}; server: {args.server}; SQLite synchronous=FULL, WAL; "
              f"{args.requests} POST /waypoints per level")
        for n, clients in enumerate(args.clients):
            r = run_level(server, peer, db_path, clients, args.requests, 10.0 + n)
            print(f"clients {clients}: {r['throughput']:7.1f} req/s ({r['acked']}/{r['sent']} acknowledged in "
                  f"{r['wall_s']:.1f} s)  HTTP {fmt(r['http_ms'])}  to topic {fmt(r['topic_ms'])}  "
                  f"server CPU {r['cpu_pct']:5.1f}% of a core  RSS {r['rss_mb']:.0f} MB  "
                  f"missing: topic {r['missing_topic']}, database {r['missing_db']}; topic order "
                  f"{'= mission order' if r['same_order'] else 'DIFFERS from mission order'}", flush=True)
    finally:
        peer.close()
        server.stop()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
