"""Several robots (issue 20): what one rover_web process costs per robot and per viewer.

    .venv/bin/python bench/fleet.py [--robots 1 5 20] [--viewers 2] [--seconds 20]
                                    [--odom-max-hz 1000] [--estops 5] [--server flask|gunicorn]

For each N: the app serves ROVER_WEB_ROBOTS=r1,...,rN (namespaces /r1 ... /rN) in its own
process; another process (bench/fleet_load.py) publishes for every robot /<name>/odom at 50 Hz,
/<name>/fix at 5 Hz and /<name>/battery_state at 1 Hz; this process holds `--viewers` SSE
streams per robot on /robots/<name>/api/events?channels=status,odom,fix,teleop,estop (a
dashboard's worth). Phases: idle (no load, no viewers), load only, load and viewers (the
measured window), then `--estops` rounds of POST /api/estop/all (and each robot released).

Reported per N: the server's CPU (% of one core) in each phase; RSS and threads; `odom` events a
second per viewer (lowest and highest viewer: a starving robot shows as a low minimum); the
odometry's age on arrival (its wall-clock stamp, set just before the publish, to the kernel's
receive timestamp of the frame in the viewer's socket; p50, p99, and the worst robot's p99);
the e-stop/all HTTP round trip, the time until every viewer of every robot had its robot's
`estop` event, and until the last robot's /<name>/e_stop said true in ROS (in the load
generator's process); for comparison, one robot's own e-stop (POST /robots/<name>/api/estop);
GET /api/robots; every robot's link state; the load generator's lag.

ODOM_MAX_HZ: by default the app's own (10 Hz) applies, so the 50 Hz odometry reaches a viewer at
~10 Hz and a frame is the newest message when the interval is up: its age includes up to one
odometry period (20 ms) of holding. `--odom-max-hz 1000` sends every message (5x the events)
and measures the path alone.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import threading
import time

import requests
from common import WALL_MINUS_MONOTONIC, Server, SseFleet, machine, percentile, ros_env, start_peer

CHANNELS = "status,odom,fix,teleop,estop"


def names(n: int) -> list[str]:
    return [f"r{i}" for i in range(1, n + 1)]


def cpu_pct(server: Server, fleet: SseFleet | None, seconds: float, on_event=None) -> float:
    """Server CPU over `seconds`; the viewers keep reading meanwhile (their sockets must not fill)."""
    cpu0, t0 = server.cpu_seconds(), time.monotonic()
    if fleet is None:
        time.sleep(seconds)
    else:
        fleet.poll(seconds, on_event or (lambda *a: None), source=on_event is not None)
    return 100 * (server.cpu_seconds() - cpu0) / (time.monotonic() - t0)


def in_thread(fn) -> tuple[threading.Thread, dict]:
    out: dict = {}

    def run():
        try:
            out["value"] = fn()
        except Exception as exc:  # reported, not raised: the bench must still stop its processes
            out["error"] = repr(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    return thread, out


def estop_rounds(server: Server, fleet: SseFleet, robots: list[str], rounds: int) -> dict:
    """POST /api/estop/all while the viewers read: the HTTP round trip, and when the last viewer
    had its robot's `estop` event with engaged true. Then each robot released, one POST each."""
    http_ms, all_viewers_ms, missing, errors, sent_wall = [], [], 0, [], []
    session = requests.Session()
    for _ in range(rounds):
        first: dict = {}
        sent_wall.append(time.time())
        t_send = time.monotonic()

        def engage(t_send=t_send):
            reply = session.post(server.url + "/api/estop/all", json={"by": "bench"}, timeout=10)
            took = time.monotonic() - t_send
            body = reply.json()
            if reply.status_code != 200 or not body.get("engaged") or set(body["robots"]) != set(robots):
                raise RuntimeError(f"estop/all answered {reply.status_code} {str(body)[:200]}")
            return took

        def on_event(_woken, t_arrived, name, data, src, first=first):
            if name == "estop" and data.get("engaged") and src not in first:
                first[src] = t_arrived

        thread, out = in_thread(engage)
        while thread.is_alive():  # the viewers keep reading while the request runs, however long
            fleet.poll(0.25, on_event, source=True)
        fleet.poll(1.0, on_event, source=True)
        if "error" in out:
            errors.append(out["error"])
            continue
        http_ms.append(1000 * out["value"])
        missing += fleet.open_count - len(first)
        if first:
            all_viewers_ms.append(1000 * (max(first.values()) - t_send))

        def release():
            for name in robots:
                reply = session.post(f"{server.url}/robots/{name}/api/estop", json={"engaged": False}, timeout=10)
                if reply.status_code != 200 or reply.json().get("engaged"):
                    raise RuntimeError(f"release of {name} answered {reply.status_code} {reply.text[:200]}")

        thread, out = in_thread(release)
        while thread.is_alive():
            fleet.poll(0.5, lambda *a: None)
        fleet.poll(0.5, lambda *a: None)
        if "error" in out:
            errors.append(out["error"])

    # For comparison: one robot's own e-stop (the last robot's), engaged and released, as often.
    last = f"{server.url}/robots/{robots[-1]}/api/estop"
    single_ms = []
    for _ in range(rounds):
        def one():
            t0 = time.monotonic()
            session.post(last, json={"engaged": True}, timeout=10).raise_for_status()
            took = time.monotonic() - t0
            session.post(last, json={"engaged": False}, timeout=10).raise_for_status()
            return took

        thread, out = in_thread(one)
        while thread.is_alive():
            fleet.poll(0.25, lambda *a: None)
        if "error" in out:
            errors.append(out["error"])
        else:
            single_ms.append(1000 * out["value"])
        fleet.poll(0.25, lambda *a: None)
    return {"http_ms": http_ms, "all_viewers_ms": all_viewers_ms, "missing": missing, "errors": errors,
            "sent_wall": sent_wall, "single_http_ms": single_ms}


def estop_in_ros(sent_wall: list[float], log: list, robots: list[str]) -> tuple[list[float], int]:
    """Per round: ms from the POST to the last robot's /<name>/e_stop true (the load generator's log)."""
    took, missing = [], 0
    for i, t_send in enumerate(sent_wall):
        t_next = sent_wall[i + 1] if i + 1 < len(sent_wall) else float("inf")
        arrived = {}
        for name, engaged, t in log:
            if engaged and t_send <= t < t_next and name not in arrived:
                arrived[name] = t
        missing += len(robots) - len(arrived)
        if arrived:
            took.append(1000 * (max(arrived.values()) - t_send))
    return took, missing


def robots_api(server: Server, fleet: SseFleet, times: int = 20) -> tuple[list[float], list[str]]:
    """GET /api/robots (the fleet page's table), while the viewers keep reading; and the links."""
    took, links = [], []
    session = requests.Session()
    for _ in range(times):
        t0 = time.monotonic()
        body = session.get(server.url + "/api/robots", timeout=10).json()
        took.append(1000 * (time.monotonic() - t0))
        links = [robot["link"] for robot in body["robots"]]
        fleet.poll(0.05, lambda *a: None)
    return took, links


def run(n: int, args, env: dict) -> dict:
    robots = names(n)
    streams = n * args.viewers
    extra = {"ROVER_WEB_ROBOTS": ",".join(robots), "ROVER_WEB_MAX_STREAMS": str(max(64, streams + 16)),
             "ROVER_WEB_SSE_MAX_CLIENTS": str(max(256, streams + 16))}
    if args.odom_max_hz:
        extra["ROVER_WEB_ODOM_MAX_HZ"] = str(args.odom_max_hz)
    server = Server({**env, **extra}, kind=args.server)
    load: subprocess.Popen | None = None
    fleet: SseFleet | None = None
    result: dict = {"n": n, "viewers": args.viewers, "loadavg": [os.getloadavg()[0]]}
    try:
        time.sleep(2.0)  # start-up's own work (first discovery, the first status) is not idle
        result["idle_cpu"] = cpu_pct(server, None, args.idle_seconds)
        result["idle_rss"] = server.rss_mb()
        t_load = time.monotonic()
        load = start_peer("fleet_load.py", env, "--robots", ",".join(robots), "--seconds", "3600")
        result["discovery_s"] = time.monotonic() - t_load
        time.sleep(1.0)
        result["load_cpu"] = cpu_pct(server, None, args.idle_seconds)

        fleet = SseFleet(server.url, [f"/robots/{name}/api/events?channels={CHANNELS}" for name in robots],
                         args.viewers)
        fleet.poll(2.0, lambda *a: None)  # snapshots and warm-up
        odom: dict[tuple, list[float]] = {}
        counts: dict[tuple, dict[str, int]] = {}

        def on_event(_woken, t_arrived, name, data, src):
            per = counts.setdefault(src, {})
            per[name] = per.get(name, 0) + 1
            if name == "odom" and data.get("stamp"):
                odom.setdefault(src, []).append(t_arrived + WALL_MINUS_MONOTONIC - data["stamp"])

        bytes0 = fleet.bytes_received
        t0 = time.monotonic()
        result["cpu"] = cpu_pct(server, fleet, args.seconds, on_event)
        window = time.monotonic() - t0
        result["kbps_per_viewer"] = (fleet.bytes_received - bytes0) / window / 1000 / max(1, streams)
        result["rss"] = server.rss_mb()
        result["threads"] = server.ps.num_threads()
        result["open_viewers"] = fleet.open_count
        result["silent_viewers"] = streams - len(counts)
        rates = [per.get("odom", 0) / window for per in counts.values()] or [0.0]
        fixes = [per.get("fix", 0) / window for per in counts.values()] or [0.0]
        result["odom_hz"] = (min(rates), max(rates))
        result["fix_hz"] = (min(fixes), max(fixes))
        every = [x for values in odom.values() for x in values]
        by_robot: dict[str, list[float]] = {}
        for (path, _), values in odom.items():
            by_robot.setdefault(path, []).extend(values)
        result["odom_ms"] = ((1000 * statistics.median(every), 1000 * percentile(every, 99)) if every
                             else (float("nan"), float("nan")))
        result["worst_robot_p99_ms"] = max((1000 * percentile(v, 99) for v in by_robot.values()), default=float("nan"))
        result["odom_events"] = len(every)

        result["estop"] = estop_rounds(server, fleet, robots, args.estops)
        result["robots_api_ms"], links = robots_api(server, fleet)
        result["links"] = {state: links.count(state) for state in sorted(set(links))}
        result["loadavg"].append(os.getloadavg()[0])
        status = requests.get(server.url + "/api/status", timeout=10).json()
        result["callback_errors"] = status.get("callback_errors")
        return result
    finally:
        if fleet is not None:
            fleet.close()
        if load is not None:
            load.terminate()
            try:
                out, _ = load.communicate(timeout=10)
                lines = [line for line in out.splitlines() if line.startswith("{")]
                if lines:
                    result["load"] = json.loads(lines[-1])
                    if "estop" in result:
                        result["estop"]["ros_ms"], result["estop"]["ros_missing"] = estop_in_ros(
                            result["estop"]["sent_wall"], result["load"].pop("estop"), robots)
            except subprocess.TimeoutExpired:
                load.kill()
                load.wait(5)
        server.stop()


def ms_pair(values: list[float]) -> str:
    if not values:
        return "—"
    return f"{statistics.median(values):.0f} / {max(values):.0f}"


def describe(r: dict) -> str:
    e = r["estop"]
    load = r.get("load") or {}
    return (f"N={r['n']:2d} viewers {r['n'] * r['viewers']:3d}: CPU idle {r['idle_cpu']:.1f}% load-only "
            f"{r['load_cpu']:.1f}% with viewers {r['cpu']:.1f}%  RSS {r['idle_rss']:.0f}->{r['rss']:.0f} MB  "
            f"threads {r['threads']}  odom/viewer {r['odom_hz'][0]:.1f}-{r['odom_hz'][1]:.1f} Hz  "
            f"fix {r['fix_hz'][0]:.1f}-{r['fix_hz'][1]:.1f} Hz  {r['kbps_per_viewer']:.1f} kB/s a viewer  "
            f"odom age p50 {r['odom_ms'][0]:.1f} p99 {r['odom_ms'][1]:.1f} ms (worst robot p99 "
            f"{r['worst_robot_p99_ms']:.1f}, n={r['odom_events']})  estop/all HTTP p50/max "
            f"{ms_pair(e['http_ms'])} ms, at every viewer {ms_pair(e['all_viewers_ms'])} ms, missed {e['missing']}, "
            f"every robot's /e_stop true in ROS {ms_pair(e.get('ros_ms', []))} ms, missed {e.get('ros_missing')}, "
            f"one robot's own e-stop HTTP {ms_pair(e['single_http_ms'])} ms, "
            f"errors {e['errors'] or 0}  /api/robots p50 {statistics.median(r['robots_api_ms']):.1f} ms  "
            f"links {r['links']}  silent viewers {r['silent_viewers']}  callback errors {r['callback_errors']}  "
            f"discovery {r['discovery_s']:.1f} s  machine load average {r['loadavg'][0]:.1f}->{r['loadavg'][-1]:.1f}"
            f"  load sent {load.get('rates')} late p99 {load.get('late_p99_ms')} ms")


def table(results: list[dict]) -> str:
    head = ("| robots | viewers | CPU idle | CPU load only | CPU load + viewers | RSS | threads | odom / viewer | "
            "odom age p50 / p99 (worst robot) | e-stop/all HTTP p50 / max | at every viewer p50 / max | "
            "last robot's /e_stop p50 / max | one robot's e-stop HTTP p50 / max | "
            "/api/robots p50 | load average |")
    rows = [head, "|" + " --- |" * (head.count("|") - 1)]
    for r in results:
        e = r["estop"]
        rows.append(
            f"| {r['n']} | {r['n'] * r['viewers']} | {r['idle_cpu']:.1f}% | {r['load_cpu']:.1f}% | {r['cpu']:.1f}% | "
            f"{r['rss']:.0f} MB | {r['threads']} | {r['odom_hz'][0]:.1f}-{r['odom_hz'][1]:.1f} Hz | "
            f"{r['odom_ms'][0]:.1f} / {r['odom_ms'][1]:.1f} ({r['worst_robot_p99_ms']:.1f}) ms | "
            f"{ms_pair(e['http_ms'])} ms | {ms_pair(e['all_viewers_ms'])} ms | {ms_pair(e.get('ros_ms', []))} ms | "
            f"{ms_pair(e['single_http_ms'])} ms | {statistics.median(r['robots_api_ms']):.1f} ms | "
            f"{r['loadavg'][0]:.1f}-{r['loadavg'][-1]:.1f} |")
    return "\n".join(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 5, 20], help="fleet sizes to run, in turn")
    parser.add_argument("--viewers", type=int, default=2, help="SSE streams per robot")
    parser.add_argument("--seconds", type=float, default=20.0, help="the measured window with load and viewers")
    parser.add_argument("--idle-seconds", type=float, default=4.0, help="each of the idle and load-only phases")
    parser.add_argument("--estops", type=int, default=5, help="rounds of POST /api/estop/all")
    parser.add_argument("--odom-max-hz", type=float, default=None,
                        help="ROVER_WEB_ODOM_MAX_HZ (default: the app's, 10)")
    parser.add_argument("--server", choices=("flask", "gunicorn"), default="flask")
    args = parser.parse_args()
    env = ros_env()
    print(f"# fleet bench on {machine()}, ROS_DOMAIN_ID {env['ROS_DOMAIN_ID']}, {args.server}, "
          f"ODOM_MAX_HZ {args.odom_max_hz or 'default'}: per robot odom 50 Hz, fix 5 Hz, battery 1 Hz; "
          f"{args.viewers} viewers a robot on {CHANNELS}", flush=True)
    results = []
    for n in args.robots:
        results.append(run(n, args, env))
        print(describe(results[-1]), flush=True)
    print()
    print(table(results))


if __name__ == "__main__":
    main()
