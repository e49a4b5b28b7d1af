"""The simulator's Nav2 planner: how long a plan takes across the basement, and how long it is.

Plans from the Dock to every waypoint of the first floorplan (and from every waypoint to every
other), in this process, pure Python (rover_web/sim/planner.py); the simulator plans once per goal
and per FollowWaypoints waypoint, on its executor, so a plan's time is a stall of its 50 Hz tick.

    .venv/bin/python bench/nav2_planner.py [--repeat 3]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from rover_web.sim.planner import GridPlanner, PlanError, path_length  # noqa: E402
from rover_web.sim.rover import first_map  # noqa: E402
from rover_web.sim.walls import Walls  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    definition = first_map()
    walls = Walls.of_map(definition)
    t0 = time.perf_counter()
    planner = GridPlanner(walls)
    build_ms = (time.perf_counter() - t0) * 1000
    points = [(w.x, w.y) for w in definition.waypoints]
    times_ms, stretch, refused = [], [], 0
    for _ in range(args.repeat):
        for a in points:
            for b in points:
                if a == b:
                    continue
                t = time.perf_counter()
                try:
                    path = planner.plan(a, b)
                except PlanError:
                    refused += 1
                    continue
                times_ms.append((time.perf_counter() - t) * 1000)
                stretch.append(path_length(path) / math.hypot(b[0] - a[0], b[1] - a[1]))
    times_ms.sort()
    result = {
        "bench": "nav2_planner", "map": definition.name, "grid": list(planner.blocked.shape),
        "build_ms": round(build_ms, 2), "plans": len(times_ms), "refused": refused // args.repeat,
        "plan_ms_median": round(statistics.median(times_ms), 2),
        "plan_ms_p90": round(times_ms[int(0.9 * (len(times_ms) - 1))], 2),
        "plan_ms_max": round(times_ms[-1], 2),
        "length_over_straight_median": round(statistics.median(stretch), 3),
    }
    print(f"{definition.name}: {len(points)} waypoints, {result['plans']} plans, grid {result['grid']}")
    print(json.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
