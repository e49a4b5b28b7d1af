"""The third security review's hostile inputs (issue 40) against a running server: each hostile MCAP file
of the review (tests/support/hostile_mcap.py, at the review's sizes) uploaded and, when stored, its
timeline asked for (the attachment bomb after a restart, as the review did), then a peer in another
process publishing a 200,000-marker array to a watched `markers` channel.

For each: the server's CPU seconds and RSS growth (peak, sampled every 20 ms, over the RSS before),
and the e-stop's GET latency (a client asks every 20 ms meanwhile). Targets: each file refused or
served within 2 s of CPU and < 100 MB RSS growth, e-stop GET p99 < 50 ms; the markers: < 100 MB RSS
growth, e-stop p99 < 50 ms, overlay CPU < 10 % of a core afterwards. Also the figures behind the
choice of decoding in the server's process rather than a worker (docs/security.md): what a worker
process costs to start and hold, against what a bounded read costs.

    .venv/bin/python bench/hostile.py [--quick]      # --quick: smaller bombs (still over every cap)
    .venv/bin/python bench/hostile.py --markers-only # the marker array alone
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import requests
from common import ROOT, Server, SseFleet, machine, percentile, ros_env, start_peer, stop_process

sys.path.insert(0, str(ROOT))
from tests.support import hostile_mcap as hostile  # noqa: E402

MIB = 1 << 20


class Monitor:
    """Pings GET /api/estop and samples the server's RSS every 20 ms until stop()."""

    def __init__(self, server: Server):
        self.server = server
        self.latencies: list[float] = []
        self.peak_mb = server.rss_mb()
        self._stop = threading.Event()
        self._threads = [threading.Thread(target=self._ping, daemon=True),
                         threading.Thread(target=self._sample, daemon=True)]
        for t in self._threads:
            t.start()

    def _ping(self) -> None:
        session = requests.Session()
        while not self._stop.is_set():
            t0 = time.perf_counter()
            try:
                session.get(self.server.url + "/api/estop", timeout=10)
                self.latencies.append(time.perf_counter() - t0)
            except requests.RequestException:
                self.latencies.append(10.0)
            self._stop.wait(0.02)

    def _sample(self) -> None:
        while not self._stop.is_set():
            try:
                self.peak_mb = max(self.peak_mb, self.server.rss_mb())
            except Exception:  # noqa: BLE001 - the process ended (a restart)
                return
            self._stop.wait(0.02)

    def stop(self) -> dict:
        self._stop.set()
        for t in self._threads:
            t.join(15)
        ms = [x * 1000 for x in self.latencies]
        return {"estop_p99_ms": round(percentile(ms, 99), 1), "estop_max_ms": round(max(ms), 1) if ms else None,
                "estop_n": len(ms), "peak_mb": round(self.peak_mb, 1)}


def upload(server: Server, path: Path):
    with open(path, "rb") as f:
        return requests.post(server.url + "/api/recordings/upload?name=hostile", data=f,
                             headers={"Content-Type": "application/octet-stream"}, timeout=120)


def measured(server: Server, action, window_s: float = 3.0) -> dict:
    """The action again and again for window_s (one e-stop p99 over enough GETs), each one's CPU the
    server's CPU over the window divided by how many ran (the pinger's own requests included)."""
    rss0, cpu0 = server.rss_mb(), server.cpu_seconds()
    monitor = Monitor(server)
    t0 = time.monotonic()
    runs, walls, first_peak = 0, [], None
    while runs == 0 or time.monotonic() - t0 < window_s:
        started = time.monotonic()
        answer = action()
        walls.append(time.monotonic() - started)
        runs += 1
        if first_peak is None:
            time.sleep(0.05)  # one more RSS sample
            first_peak = max(monitor.peak_mb, server.rss_mb())
        time.sleep(0.25)  # one attacker's file after another, not a flood of uploads (that is the rate limit's)
    cpu1 = server.cpu_seconds()
    m = monitor.stop()
    return {"answer": answer, "runs": runs, "cpu_s": round((cpu1 - cpu0) / runs, 3), "wall_s": round(max(walls), 3),
            "first_rss_growth_mb": round(first_peak - rss0, 1), "rss_growth_mb": round(m["peak_mb"] - rss0, 1),
            **{k: v for k, v in m.items() if k != "peak_mb"}}


def answer_of(response) -> str:
    body = response.json() if response.headers.get("Content-Type") == "application/json" else {}
    return f"{response.status_code} {body.get('error', '')}".strip()


def files(folder: Path, quick: bool) -> dict[str, Path]:
    scale = 8 if quick else 1
    made = {
        "zstd_bomb (2 GiB declared and held)": hostile.zstd_bomb(folder / "zstd.mcap", held=2 * (1 << 30) // scale),
        "lz4_bomb (1 GiB held, 1 KiB declared)": hostile.lz4_bomb(folder / "lz4.mcap", held=(1 << 30) // scale),
        "amplification (8 MB of empty messages)": hostile.amplification(folder / "amp1.mcap"),
        "amplification x5000 (as Odometry)": hostile.amplification(folder / "amp5000.mcap", copies=5000),
        "many_fields (200,000 fields)": hostile.many_fields(folder / "fields.mcap"),
        "many_fields (2,500 fields, under the size cap)": hostile.many_fields(folder / "fields2500.mcap", fields=2500),
        "many_chunks (100 x 32 MiB)": hostile.many_chunks(folder / "chunks.mcap"),
    }
    made["attachment_bomb (after a restart)"] = hostile.attachment_bomb(folder / "attach.mcap",
                                                                       held=2 * (1 << 30) // scale)
    return made


def run_files(env: dict, quick: bool) -> list[dict]:
    out = []
    with tempfile.TemporaryDirectory(prefix="rover_web-hostile-") as tmp:
        tmp = Path(tmp)
        env = {**env, "ROVER_WEB_DB_PATH": str(tmp / "db.sqlite3"), "ROVER_WEB_RECORDINGS_DIR": str(tmp / "rec")}
        built = files(tmp, quick)
        server = Server(env)
        try:
            requests.get(server.url + "/api/estop", timeout=10)  # the route's first answer is not the one measured
            base = measured(server, lambda: time.sleep(0.5) or "idle")
            base.update(file="baseline: nothing hostile, 3 s", size=0)
            out.append(base)
            print(f"baseline (idle 3 s): CPU {base['cpu_s']} s, e-stop p99 {base['estop_p99_ms']} ms "
                  f"(max {base['estop_max_ms']} ms, n={base['estop_n']})", flush=True)
            for name, path in built.items():
                if name.startswith("attachment"):
                    made = upload(server, path)
                    stored = answer_of(made)
                    server.stop()
                    server = Server(env)  # the index the upload built is gone: the file is read again
                    url = f"{server.url}/api/recordings/{made.json().get('id')}/timeline"
                    first_read = lambda url=url: answer_of(requests.get(url, timeout=120))  # noqa: E731
                    r = measured(server, first_read, 0.0)  # once: later reads are answered from the cache
                    r["answer"] = f"upload {stored}; timeline {r['answer']}"
                else:
                    r = measured(server, lambda path=path, server=server: answer_of(upload(server, path)))
                r.update(file=name, size=path.stat().st_size)
                out.append(r)
                print(f"{name:48s} {r['size']:>9d} B  {r['answer']:28s} x{r['runs']:<3d} "
                      f"CPU {r['cpu_s']:6.3f} s each  RSS +{r['first_rss_growth_mb']:6.1f} MB first, "
                      f"+{r['rss_growth_mb']:6.1f} MB all  e-stop p99 {r['estop_p99_ms']:6.1f} ms "
                      f"(max {r['estop_max_ms']} ms, n={r['estop_n']})", flush=True)
        finally:
            server.stop()
    return out


def run_markers(env: dict, markers: int) -> dict:
    server = Server(env)
    fleet = SseFleet(server.url, "/api/events?channels=markers", 1)
    sizes: list[int] = []
    try:
        fleet.poll(0.5, lambda *a: None)
        rss0, cpu0 = server.rss_mb(), server.cpu_seconds()
        monitor = Monitor(server)
        pub = start_peer("marker_flood.py", env, "--markers", str(markers), "--times", "6", "--period", "2")

        def heard() -> int:
            layer = requests.get(server.url + "/api/overlays", timeout=10).json()["layers"]["markers"]
            return layer["received"] + layer["skipped_by_reason"].get("too_large", 0)

        deadline = time.monotonic() + 25  # DDS reassembles a 40 MB sample slowly on a loaded machine
        while time.monotonic() < deadline and (heard() < 2 or pub.poll() is None):
            fleet.poll(1.0, lambda _tw, _ta, name, data: sizes.append(len(data.get("markers", []))))
            if pub.poll() is not None and heard() >= 1:
                break
        stop_process(pub)
        during_cpu = server.cpu_seconds() - cpu0
        m = monitor.stop()
        cpu_a, t_a = server.cpu_seconds(), time.monotonic()
        fleet.poll(5.0, lambda *a: None)  # still watched: what the overlays cost afterwards
        after_pct = 100 * (server.cpu_seconds() - cpu_a) / (time.monotonic() - t_a)
        counts = requests.get(server.url + "/api/overlays", timeout=5).json()["layers"]["markers"]
        kept = server.rss_mb() - rss0  # what stays once it is over (a reader's pool kept the sample)
        r = {"markers": markers, "rss_growth_mb": round(m["peak_mb"] - rss0, 1), "rss_kept_mb": round(kept, 1),
             "estop_p99_ms": m["estop_p99_ms"],
             "estop_max_ms": m["estop_max_ms"], "cpu_during_s": round(during_cpu, 2),
             "cpu_after_pct": round(after_pct, 1), "largest_frame_markers": max(sizes, default=0),
             "skipped_by_reason": counts["skipped_by_reason"]}
        print(f"{markers} markers: RSS +{r['rss_growth_mb']} MB at peak, +{r['rss_kept_mb']} MB kept, "
              f"e-stop p99 {r['estop_p99_ms']} ms (max {r['estop_max_ms']}), CPU during {r['cpu_during_s']} s, "
              f"after {r['cpu_after_pct']} % of a core, "
              f"largest frame {r['largest_frame_markers']} markers, skipped {r['skipped_by_reason']}", flush=True)
        return r
    finally:
        fleet.close()
        server.stop()


def worker_figures(folder: Path) -> dict:
    """A worker process per read, against the read in this process."""
    from rover_web.recording.file_index import walk

    small = hostile.amplification(folder / "small.mcap", length=1024)  # a bounded read's floor
    t0 = time.perf_counter()
    walk(small)
    in_process_ms = (time.perf_counter() - t0) * 1000
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    code = ("import resource, pathlib; resource.setrlimit(resource.RLIMIT_AS, (512 << 20, 512 << 20)); "
            f"from rover_web.recording.file_index import walk; walk(pathlib.Path({str(small)!r})); "
            "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)")
    done = subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT, capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    spawn_ms = (time.perf_counter() - t0) * 1000
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = {"in_process_read_ms": round(in_process_ms, 2), "worker_spawn_read_ms": round(spawn_ms, 1),
         "worker_cpu_s": round((after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime), 3),
         "worker_peak_rss_mb": round(int(done.stdout.split()[-1]) / 1024, 1)}
    print(f"a read in this process {r['in_process_read_ms']} ms; in a spawned worker (RLIMIT_AS 512 MB) "
          f"{r['worker_spawn_read_ms']} ms wall, {r['worker_cpu_s']} s CPU, peak RSS {r['worker_peak_rss_mb']} MB",
          flush=True)
    return r


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--markers", type=int, default=200_000)
    parser.add_argument("--markers-only", action="store_true", help="the marker array alone, not the files")
    args = parser.parse_args()
    print(machine(), "(shared with other sessions: figures from a loaded machine)")
    env = ros_env()
    if args.markers_only:
        markers = run_markers(env, args.markers)
        ok = markers["rss_growth_mb"] < 100 and markers["estop_p99_ms"] < 50 and markers["cpu_after_pct"] < 10
        print(json.dumps({"bench": "hostile_markers", "markers": markers, "markers_within_targets": ok}))
        return
    with tempfile.TemporaryDirectory() as tmp:
        worker = worker_figures(Path(tmp))
    results = run_files(env, args.quick)
    markers = run_markers(env, args.markers)
    ok_files = all(r["cpu_s"] < 2 and r["first_rss_growth_mb"] < 100 and r["estop_p99_ms"] < 50 for r in results[1:])
    ok_markers = markers["rss_growth_mb"] < 100 and markers["estop_p99_ms"] < 50 and markers["cpu_after_pct"] < 10
    print(json.dumps({"bench": "hostile", "files": results, "markers": markers, "worker": worker,
                      "files_within_targets": ok_files, "markers_within_targets": ok_markers}))


if __name__ == "__main__":
    main()
