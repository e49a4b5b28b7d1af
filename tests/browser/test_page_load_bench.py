"""bench/page_load.py and bench/sse_compression.py run, with a tiny setting, and their last line is the
JSON the results in BENCHMARKS.md are read from (the figures themselves are the benches', not asserted)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.browser

ROOT = Path(__file__).resolve().parents[2]
FIGURES = {"bytes", "wire_bytes", "requests", "ttfb_ms", "estop_ms", "live_ms", "whole_ms", "floor_ms",
           "static_requests", "dcl_ms"}


def run_bench(*args: str, timeout: float) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROVER_WEB_")}
    env["ROS_DOMAIN_ID"] = os.environ.get("ROVER_WEB_TEST_DOMAIN_ID", os.environ.get("ROS_DOMAIN_ID", "0"))
    done = subprocess.run([sys.executable, *args], cwd=ROOT, env=env, capture_output=True, text=True, timeout=timeout)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_the_page_load_bench_prints_its_figures_as_json():
    result = run_bench("bench/page_load.py", "--profile", "loopback", "--pages", "waypoints", "--timeout", "40",
                       timeout=240)
    assert result["bench"] == "page_load" and result["profile"] == "custom" and result["preload"] is True
    page = result["pages"]["waypoints"]
    assert "error" not in page, page
    for kind in ("cold", "warm"):
        assert set(page[kind]) == FIGURES
        assert page[kind]["requests"] >= 1 and page[kind]["bytes"] > 0
        assert page[kind]["estop_ms"] is not None and page[kind]["live_ms"] >= page[kind]["ttfb_ms"]
    assert page["cold"]["static_requests"] > 0
    assert page["warm"]["static_requests"] == 0  # a warm reload asks for no static file


def test_the_sse_compression_bench_prints_its_figures_as_json():
    result = run_bench("bench/sse_compression.py", "--seconds", "0.2", "--viewers", "1", "2", timeout=60)
    assert result["bench"] == "sse_compression"
    for codec in ("gzip", "br-4", "br-1"):
        for viewers in ("1", "2"):
            assert set(result["codecs"][codec][viewers]) == {"bytes_per_event", "saved", "cpu_us_per_event_per_viewer",
                                                             "cpu_share_at_100hz"}
