"""The fleet hub (issue 31): one hub hearing N robots over Zenoh, and a stop-all to all of them.

    .venv/bin/python bench/hub.py [--robots 100] [--processes 2] [--seconds 20] [--stops 3] [--router]

The hub is `ROVER_WEB_HUB=true flask run` in its own process (Zenoh listening on a free
127.0.0.1 port; multicast scouting off). The robots are light: `--processes` child processes of
this script, each one Zenoh client session holding its share of the robots, each robot a
liveliness token, a stop queryable that checks the signed command (rover_web.zenoh_link.signing)
and answers signed, and a signed summary of the real shape published at 1 Hz (phases spread).
No ROS and no rover_web in them: the hub's cost is what is measured.

--router puts a Zenoh router between them, as a site with one router per network would: a
session in `router` mode in a process of its own (eclipse-zenoh's Python package runs one; no
zenohd needed), the hub and every robot process its clients.

Reported: the hub's CPU (% of one core) over the measured window, with every robot heard;
the summaries' age on the hub (`summary_age_s` of GET /api/robots, sampled every 0.5 s for every
robot: how old what an operator sees is; a 1 Hz robot's is 0-1 s by design) p50/p99/max; then
`--stops` rounds of POST /api/estop/all: the HTTP round trip, the hub's own `took_s` (first
command sent to last answer in), and how many robots answered engaged. Issue 42: the cost of one
GET /metrics with every robot heard (server CPU per scrape, bench/metrics.py's way; its size and
series; target <= 20 ms at 100 robots) and the size of the /robots page. One JSON line last.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time

import requests
from common import ROOT, Server, free_port, machine, percentile, ros_env, stop_process
from metrics import scrape_cost

FLEET = "bench"


def robot_summary(name: str, engaged: bool) -> dict:
    """What a rover_web robot publishes (rover_web/zenoh_link/robot.py), with plausible values."""
    return {"name": name, "namespace": f"/{name}", "kind": "rover", "title": name, "url": None, "link": "ok",
            "mode": "estop" if engaged else "idle", "operator": None,
            "speed": {"linear_mps": 0.0, "angular_rps": 0.0}, "battery": {"percent": 80.0, "voltage": 24.1},
            "estop": {"engaged": engaged, "since": None, "by": None}, "position": {"lng": 8.5, "lat": 47.4},
            "alerts": []}


def child(endpoint: str, key_file: str, names: list[str]) -> None:
    """One process of simulated robots, until stdin closes."""
    import zenoh

    from rover_web.zenoh_link import signing

    key = signing.load_key(key_file)
    config = zenoh.Config()
    config.insert_json5("mode", '"client"')  # a client listens on nothing: nothing opened beyond the hub link
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    session = zenoh.open(config)
    engaged = dict.fromkeys(names, False)
    guards = {name: signing.ReplayGuard(10.0) for name in names}

    def on_stop(name, query):
        payload = query.payload.to_bytes() if query.payload else b""
        try:
            command = guards[name].check(key, FLEET, name, json.loads(payload))
            engaged[name] = True
            reply = signing.answer(key, FLEET, name, command["nonce"], "engaged")
        except (ValueError, signing.CommandRefused) as exc:
            reply = signing.answer(key, FLEET, name, "", "refused", message=str(exc))
        query.reply(query.key_expr, json.dumps(reply).encode())

    declared = []
    publishers = {}
    for name in names:
        publishers[name] = session.declare_publisher(f"rover_web/{FLEET}/{name}/summary")
        declared.append(session.liveliness().declare_token(f"rover_web/{FLEET}/{name}/alive"))
        declared.append(session.declare_queryable(f"rover_web/{FLEET}/{name}/stop",
                                                  lambda q, name=name: on_stop(name, q)))
    done = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.read(), done.set()), daemon=True).start()
    print("robots ready", flush=True)
    seq = 0
    step = 1.0 / len(names)  # each robot at 1 Hz, their phases spread over the second
    next_at = time.monotonic()
    while not done.is_set():
        seq += 1
        for name in names:
            next_at += step
            delay = next_at - time.monotonic()
            if delay > 0 and done.wait(delay):
                break
            publishers[name].put(signing.signed_summary(key, FLEET, name, seq, robot_summary(name, engaged[name])))
    for item in declared:
        item.undeclare()
    session.close()


def router(endpoint: str) -> None:
    """A Zenoh router on `endpoint`, until stdin closes."""
    import zenoh

    config = zenoh.Config()
    config.insert_json5("mode", '"router"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", json.dumps([endpoint]))
    session = zenoh.open(config)
    print("router ready", flush=True)
    sys.stdin.read()
    session.close()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", type=int, default=100)
    parser.add_argument("--processes", type=int, default=2)
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--stops", type=int, default=3)
    parser.add_argument("--scrapes", type=int, default=100, help="GET /metrics back to back, for its cost")
    parser.add_argument("--router", action="store_true", help="through a Zenoh router process (clients of it)")
    parser.add_argument("--router-child", metavar="ENDPOINT", help=argparse.SUPPRESS)
    parser.add_argument("--child", nargs=3, metavar=("ENDPOINT", "KEY_FILE", "NAMES"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child[0], args.child[1], args.child[2].split(","))
        return
    if args.router_child:
        router(args.router_child)
        return

    tmp = tempfile.TemporaryDirectory(prefix="rover_web-bench-hub-")
    key_file = os.path.join(tmp.name, "fleet.key")
    with open(os.open(key_file, os.O_WRONLY | os.O_CREAT, 0o600), "w") as fh:  # the hub refuses a looser key
        fh.write(os.urandom(32).hex())
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    zrouter = None
    if args.router:  # the router listens; the hub connects to it as a client, as the robots do
        zrouter = subprocess.Popen([sys.executable, __file__, "--router-child", endpoint], cwd=ROOT, env=ros_env(),
                                   stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        if "router ready" not in zrouter.stdout.readline():
            stop_process(zrouter)
            raise RuntimeError("the Zenoh router did not start")
        link = {"ROVER_WEB_ZENOH_MODE": "client", "ROVER_WEB_ZENOH_CONNECT": endpoint}
    else:
        link = {"ROVER_WEB_ZENOH_MODE": "peer", "ROVER_WEB_ZENOH_LISTEN": endpoint}
    try:
        hub = Server(ros_env(ROVER_WEB_HUB="true", ROVER_WEB_FLEET_NAME=FLEET, ROVER_WEB_FLEET_KEY_FILE=key_file,
                             **link))
    except BaseException:
        if zrouter is not None:
            zrouter.stdin.close()
            stop_process(zrouter)
        raise
    names = [f"r{i:03d}" for i in range(args.robots)]
    shares = [names[i::args.processes] for i in range(args.processes)]
    children = [subprocess.Popen([sys.executable, __file__, "--child", endpoint, key_file, ",".join(share)],
                                 cwd=ROOT, env=ros_env(), stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
                for share in shares if share]
    try:
        for proc in children:
            if "robots ready" not in proc.stdout.readline():
                raise RuntimeError("a robot process did not start")
        deadline = time.monotonic() + 30
        while True:
            robots = requests.get(hub.url + "/api/robots", timeout=5).json()["robots"]
            if sum(r["heard"] == "live" for r in robots) == args.robots:
                break
            if time.monotonic() > deadline:
                raise RuntimeError(f"only {sum(r['heard'] == 'live' for r in robots)} robots live after 30 s")
            time.sleep(0.5)
        print(f"{machine()}; {args.robots} robots in {len(children)} processes, 1 Hz each, {args.seconds:g} s"
              + ("; through a Zenoh router process" if args.router else "; robots connect to the hub (peer)"))

        ages: list[float] = []
        lost = 0
        cpu0, t0 = hub.cpu_seconds(), time.monotonic()
        while time.monotonic() - t0 < args.seconds:
            for line in requests.get(hub.url + "/api/robots", timeout=5).json()["robots"]:
                lost += line["heard"] != "live"
                if line["summary_age_s"] is not None:
                    ages.append(line["summary_age_s"])
            time.sleep(0.5)
        cpu = 100.0 * (hub.cpu_seconds() - cpu0) / (time.monotonic() - t0)
        print(f"hub CPU {cpu:.1f}% of one core (its GET /api/robots every 0.5 s included); RSS {hub.rss_mb():.0f} MB")
        print(f"summary age on the hub: p50 {percentile(ages, 50):.3f} s, p99 {percentile(ages, 99):.3f} s, "
              f"max {max(ages):.3f} s over {len(ages)} samples; lost samples: {lost}")

        scrape = scrape_cost(hub, args.scrapes, 3.0)
        print(f"hub /metrics at {args.robots} robots: {scrape['cpu_ms_per_scrape']:.2f} ms server CPU per scrape "
              f"(target <= 20), wall p50 {scrape['wall_p50_ms']:.2f} ms p99 {scrape['wall_p99_ms']:.2f} ms, "
              f"{scrape['bytes']} bytes, {scrape['series']} series")
        t = time.monotonic()
        page = requests.get(hub.url + "/robots", timeout=10)
        print(f"hub /robots page at {args.robots} robots: {len(page.content)} bytes in "
              f"{(time.monotonic() - t) * 1000:.0f} ms")
        stops = []
        for i in range(args.stops):
            t = time.monotonic()
            answer = requests.post(hub.url + "/api/estop/all", json={}, timeout=60).json()
            http_s = time.monotonic() - t
            engaged = sum(a["result"] == "engaged" for a in answer["robots"].values())
            print(f"stop-all {i + 1}: HTTP {http_s * 1000:.0f} ms, hub took_s {answer['took_s'] * 1000:.0f} ms, "
                  f"{engaged}/{args.robots} answered engaged")
            stops.append(answer["took_s"])
            time.sleep(1.0)
        print(json.dumps({"bench": "hub", "robots": args.robots, "hub_cpu_pct": round(cpu, 1),
                          "summary_age_p99_s": round(percentile(ages, 99), 3), "scrape": scrape,
                          "page_bytes": len(page.content), "stop_all_took_s": stops}))
    finally:
        for proc in children:
            try:
                proc.stdin.close()
                proc.wait(10)
            except (OSError, subprocess.TimeoutExpired):
                stop_process(proc)
        hub.stop()
        if zrouter is not None:
            zrouter.stdin.close()
            try:
                zrouter.wait(10)
            except subprocess.TimeoutExpired:
                stop_process(zrouter)
        tmp.cleanup()


if __name__ == "__main__":
    main()
