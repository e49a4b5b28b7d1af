"""Reconnect storm: how fast the e-stop answers while 200 SSE clients and 20 teleop sockets
connect and drop ten times within 10 s (half politely, half by TCP reset), and what is left after.

    .venv/bin/python bench/storm.py [--runs 3]

The storm is the one tests/integration/test_reconnect_storm.py runs (tests/support/storm.py); the
e-stop is posted every 50 ms from a process of its own. Target (issue 21): every answer within
200 ms. Run it on an otherwise idle machine: with other work on two cores the tail grows with it.
"""

from __future__ import annotations

import argparse
import sys
import time

import psutil
import requests
from common import ROOT, Server, machine, ros_env

sys.path.insert(0, str(ROOT))
from tests.support.storm import describe, storm, storm_round  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3)
    args = parser.parse_args()
    print(f"# storm bench on {machine()}", flush=True)
    for run in range(args.runs):
        server = Server(ros_env(ROVER_WEB_MAX_STREAMS="240", ROVER_WEB_SSE_MAX_CLIENTS="240"))
        try:
            proc = psutil.Process(server.proc.pid)
            storm_round(server.port, True, [], [])
            time.sleep(2.0)
            before = (proc.num_threads(), proc.num_fds(), proc.memory_info().rss / 1e6)
            result = storm(server.port)
            time.sleep(3.0)
            after = (proc.num_threads(), proc.num_fds(), proc.memory_info().rss / 1e6)
            open_now = requests.get(server.url + "/api/status", timeout=5).json()["streams"]["open"]
            print(f"run {run + 1}: {describe(result)}; threads {before[0]}->{after[0]}, fds {before[1]}->{after[1]}, "
                  f"RSS {before[2]:.1f}->{after[2]:.1f} MB, streams open after {open_now}", flush=True)
        finally:
            server.stop()


if __name__ == "__main__":
    main()
