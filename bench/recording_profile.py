"""Where the recorder's CPU goes: bench/recording.py's traffic, the app in this process, cProfile.

py-spy cannot attach on the machines this project runs on, so the app is made here
(`create_app`) and profiled from inside: cProfile in the ROS executor thread (every callback,
and rclpy's wait-set work between them), in the recording's raw taker thread and in the
recorder's writer thread, and each thread's
CPU (`/proc/self/task`) in a phase not recording and a phase recording the 20 topics with the
camera. Prints the CPU per thread in both phases and the top functions of each profile.

    .venv/bin/python bench/recording_profile.py [--seconds 15] [--top 25] [--no-profile]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import pstats
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

from common import ROOT, machine, ros_env, stop_process, wait_for
from recording import RATES

TICKS = os.sysconf("SC_CLK_TCK")


def thread_cpu() -> dict[str, float]:
    """CPU seconds per thread name: Python's names for its threads, the kernel's (Fast DDS names its
    own) for the others; threads of one name summed."""
    python_names = {t.native_id: t.name for t in threading.enumerate()}
    out: Counter = Counter()
    for task in Path("/proc/self/task").iterdir():
        try:
            name = python_names.get(int(task.name)) or (task / "comm").read_text().strip()
            fields = (task / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        out[name] += (int(fields[11]) + int(fields[12])) / TICKS  # utime, stime
    return dict(out)


def phase(seconds: float) -> tuple[dict[str, float], float]:
    before, t0 = thread_cpu(), time.monotonic()
    time.sleep(seconds)
    after, elapsed = thread_cpu(), time.monotonic() - t0
    return {name: 100 * (after.get(name, 0) - before.get(name, 0)) / elapsed for name in after}, elapsed


def top(profile: cProfile.Profile, n: int, sort: str) -> str:
    out = io.StringIO()
    pstats.Stats(profile, stream=out).strip_dirs().sort_stats(sort).print_stats(n)
    return out.getvalue()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=15.0)
    parser.add_argument("--top", type=int, default=25)
    parser.add_argument("--no-profile", action="store_true", help="CPU per thread only (cProfile slows Python)")
    args = parser.parse_args()
    folder = tempfile.TemporaryDirectory(prefix="rover_web-prof-rec-")
    env = ros_env()
    os.environ.update({k: env[k] for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")})
    publisher = subprocess.Popen([sys.executable, str(ROOT / "bench" / "recording.py"), "--publish"], cwd=ROOT,
                                 env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
    sys.path.insert(0, str(ROOT))  # this checkout's rover_web
    from rover_web import create_app
    from rover_web.recording import recorder as recorder_module
    from rover_web.ros import raw_taker

    app = create_app({"ROVER_WEB_DB_PATH": str(Path(folder.name, "db.sqlite3")),
                      "ROVER_WEB_SECRET_KEY": "profile-" + "k" * 32, "ROVER_WEB_HOST": "127.0.0.1",
                      "ROVER_WEB_RECORDINGS_DIR": str(Path(folder.name, "recordings")),
                      "ROVER_WEB_RECORDING_CAMERA_MAX_HZ": 10.0, "ROVER_WEB_RECORDINGS_MIN_FREE_MB": 100.0})
    client = app.test_client()
    writer_profile, taker_profile = cProfile.Profile(), cProfile.Profile()

    def profiled(cls, profile: cProfile.Profile) -> None:
        """cls._run (a thread's whole life) under `profile`: cProfile sees only its own thread."""
        run = cls._run

        def wrapped(self):
            if not args.no_profile:
                profile.enable()
            try:
                run(self)
            finally:
                profile.disable()
        cls._run = wrapped
    profiled(recorder_module.Recorder, writer_profile)
    profiled(raw_taker.RawTaker, taker_profile)
    runtime = app.extensions["rover_web"].runtime
    try:
        if "publishing" not in publisher.stdout.readline():
            raise RuntimeError("the publisher did not start")
        for topic in RATES:
            wait_for(lambda topic=topic: any(t["name"] == topic for t in client.get("/api/topics").json["topics"]),
                     30, f"{topic} discovered")
        idle, _ = phase(args.seconds / 2)
        executor_profile = cProfile.Profile()
        started = client.post("/api/recordings", json={"topics": list(RATES), "camera": True}).json
        if not args.no_profile:
            runtime.run_on_executor(executor_profile.enable)
        busy, _ = phase(args.seconds)
        if not args.no_profile:
            runtime.run_on_executor(executor_profile.disable)
        done = client.post(f"/api/recordings/{started['id']}/stop", json={}).json
    finally:
        publisher.stdin.close()
        stop_process(publisher)
        app.extensions["rover_web"].shutdown()
    print(f"machine: {machine()}, load average {os.getloadavg()[0]:.2f}")
    print(f"recorded {done['messages']} messages in {done['duration_s']:.1f} s, "
          f"{sum(done['dropped'].values())} dropped, {done['size'] / 1e6:.1f} MB; "
          f"/camera/image_raw {done['counts'].get('/camera/image_raw', 0)} frames, "
          f"/odom {done['counts'].get('/odom', 0)}")
    print(f"{'thread':<24} {'not recording':>14} {'recording':>10} {'difference':>10}  (% of one core)")
    for name in sorted(set(idle) | set(busy), key=lambda n: -(busy.get(n, 0) - idle.get(n, 0))):
        a, b = idle.get(name, 0.0), busy.get(name, 0.0)
        if a or b:
            print(f"{name:<24} {a:>14.1f} {b:>10.1f} {b - a:>10.1f}")
    print(f"{'all':<24} {sum(idle.values()):>14.1f} {sum(busy.values()):>10.1f} "
          f"{sum(busy.values()) - sum(idle.values()):>10.1f}")
    if not args.no_profile:
        print("\n== the ROS executor thread, by own time\n" + top(executor_profile, args.top, "tottime"))
        print("== the recording's raw taker thread, by own time\n" + top(taker_profile, args.top, "tottime"))
        print("== the recorder's writer thread, by own time\n" + top(writer_profile, args.top, "tottime"))
    folder.cleanup()


if __name__ == "__main__":
    main()
