"""Sign-in work: N anonymous sign-in attempts at once against a live server, and what they cost it.

    .venv/bin/python bench/signin.py [--parallel 8] [--rounds 5] [--kind flask|gunicorn]

Each round starts N attempts together (wrong passwords for real names and unknown names, the
way a guesser or a flood would), while the server's RSS is sampled every 5 ms. Printed: the RSS
before, the peak, and how many attempts were answered 401 (a hash was computed), 503 (refused at
once: every hashing slot taken, no hash) or 429 (throttled). Issue 27: eight parallel attempts took
the server from 109 to 633 MB with 64 MiB Argon2 hashes and no bound on how many ran at once.

The per-address limit (ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN) is raised for the run when the code has
it, so the hashing bound is what is measured, not the throttle (all attempts come from 127.0.0.1).
The back-off still counts: after 10 failures from one address its attempts wait (429), so with
the default 8 x 5 (10 of them hashed) the last round is the last one with hashes.
"""

from __future__ import annotations

import argparse
import collections
import sys
import threading
import time

import psutil
import requests
from common import ROOT, Server, machine, ros_env

sys.path.insert(0, str(ROOT))
from tests.support.auth import add_users  # noqa: E402


def rss_mb(server: Server) -> float:
    """The server's RSS with its children's: gunicorn's worker is a child of its master."""
    total = server.ps.memory_info().rss
    for child in server.ps.children(recursive=True):
        try:
            total += child.memory_info().rss
        except psutil.NoSuchProcess:
            pass
    return total / 1e6


class PeakRss:
    def __init__(self, server: Server):
        self.server = server
        self.peak = rss_mb(server)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.005):
            self.peak = max(self.peak, rss_mb(self.server))

    def stop(self) -> float:
        self._stop.set()
        self._thread.join()
        return self.peak


def one_round(url: str, parallel: int, round_no: int) -> collections.Counter:
    start = threading.Barrier(parallel)
    statuses: collections.Counter = collections.Counter()
    lock = threading.Lock()

    def attempt(i: int) -> None:
        # Unknown names new each round: a lock or back-off per name must not hide the hashing cost.
        name = ("viewer", "operator", "admin")[i % 3] if i % 2 else f"nobody{round_no}-{i}"
        start.wait()
        try:
            status = requests.post(url + "/login", json={"username": name, "password": f"guess {i} guess"},
                                   timeout=60).status_code
        except requests.RequestException as exc:
            status = type(exc).__name__
        with lock:
            statuses[status] += 1

    threads = [threading.Thread(target=attempt, args=(i,)) for i in range(parallel)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return statuses


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--parallel", type=int, default=8)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--kind", choices=("flask", "gunicorn"), default="flask")
    args = parser.parse_args()
    print(f"# sign-in bench on {machine()}: {args.parallel} parallel attempts x {args.rounds} rounds, {args.kind}",
          flush=True)
    import tempfile

    with tempfile.TemporaryDirectory(prefix="rover_web-signin-") as tmp:
        db_path = f"{tmp}/signin.sqlite3"
        add_users(db_path)  # the code under test hashes their passwords with its own parameters
        settings = {"ROVER_WEB_DB_PATH": db_path}
        if "SIGNIN_ATTEMPTS_PER_MIN" in (ROOT / "rover_web" / "config.py").read_text():
            settings["ROVER_WEB_SIGNIN_ATTEMPTS_PER_MIN"] = "10000"
        server = Server(ros_env(**settings), kind=args.kind)
        try:
            # One attempt first: the dummy hash for unknown names is made at the first sign-in.
            requests.post(server.url + "/login", json={"username": "nobody", "password": "warm up"}, timeout=60)
            time.sleep(1.0)
            before = rss_mb(server)
            total: collections.Counter = collections.Counter()
            peak_all = before
            for n in range(args.rounds):
                sampler = PeakRss(server)
                t0 = time.perf_counter()
                statuses = one_round(server.url, args.parallel, n)
                elapsed = time.perf_counter() - t0
                peak = sampler.stop()
                peak_all = max(peak_all, peak)
                total.update(statuses)
                print(f"round {n + 1}: {dict(sorted(statuses.items(), key=str))} in {elapsed * 1000:.0f} ms, "
                      f"peak RSS {peak:.1f} MB", flush=True)
                time.sleep(0.5)
            after = rss_mb(server)
            print(f"RSS before {before:.1f} MB, peak {peak_all:.1f} MB (+{peak_all - before:.1f}), "
                  f"after {after:.1f} MB; answers {dict(sorted(total.items(), key=str))}; "
                  f"503 (no hash): {total.get(503, 0)}", flush=True)
        finally:
            server.stop()


if __name__ == "__main__":
    main()
