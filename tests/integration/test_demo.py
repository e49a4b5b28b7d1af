"""`python -m rover_web.demo` (what scripts/demo.sh runs): GUI + simulator, one Ctrl-C stops both."""

import os
import re
import signal
import subprocess
import sys
import time

import psutil
import pytest
import requests

from tests.conftest import free_port
from tests.support.rospeer import ROOT, subprocess_env
from tests.support.waiting import wait_until


def links(port: int) -> dict[str, str]:
    """Each robot's link as /api/robots says it; {} while the GUI is not up yet."""
    try:
        robots = requests.get(f"http://127.0.0.1:{port}/api/robots", timeout=1).json()["robots"]
    except requests.RequestException:
        return {}
    return {r["name"]: r["link"] for r in robots}


@pytest.mark.parametrize("robots", [None, "boat,rover2"], ids=["one robot", "two namespaced robots"])
def test_demo_serves_the_simulated_robots_and_one_ctrl_c_stops_everything(tmp_path, robots):
    port = free_port()
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "demo.sqlite3"))
    extra = ["--robots", robots] if robots else []
    names = robots.split(",") if robots else ["robot"]
    # A terminal's Ctrl-C goes to the whole foreground process group: do the same.
    proc = subprocess.Popen([sys.executable, "-m", "rover_web.demo", "--port", str(port), *extra], cwd=ROOT,
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 30
        seen = {}
        while time.monotonic() < deadline:
            seen = links(port)
            if seen == dict.fromkeys(names, "ok"):
                break
            time.sleep(0.2)
        assert seen == dict.fromkeys(names, "ok"), f"the GUI never heard every simulated robot: {seen}"
        children = psutil.Process(proc.pid).children(recursive=True)
        assert any("rover_web.sim" in " ".join(c.cmdline()) for c in children)
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(15) == 0
        output = proc.stdout.read()
        assert "simulator stopped" in output
        assert "Traceback" not in output
        assert not any(c.is_running() and c.status() != psutil.STATUS_ZOMBIE for c in children)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)
        proc.stdout.close()


ACCESS_LINE = re.compile(r'"GET /\S* HTTP/1\.[01]" \d{3}')
REQUESTS = 20


@pytest.mark.parametrize("verbose", [False, True], ids=["default", "--verbose"])
def test_the_demos_terminal_has_no_request_or_debug_lines_unless_verbose(tmp_path, verbose):
    port = free_port()
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "demo.sqlite3"))
    proc = subprocess.Popen([sys.executable, "-m", "rover_web.demo", "--port", str(port), "--only", "rover",
                             *(["--verbose"] if verbose else [])], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    url = f"http://127.0.0.1:{port}"
    try:
        wait_until(lambda: links(port) == {"robot": "ok"}, 30, "the GUI hearing the simulated robot")
        for _ in range(REQUESTS):
            assert requests.get(url + "/api/status", timeout=5).ok
        # The battery's first INFO line and the first DEBUG health check are logged in the same second.
        wait_until(lambda: requests.get(url + "/api/rosout", params={"contains": "battery at"}, timeout=5)
                   .json()["lines"], 20, "the simulator's first log line")
        os.killpg(proc.pid, signal.SIGINT)
        assert proc.wait(15) == 0
        output = proc.stdout.read()
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)
        proc.stdout.close()
    assert "rover_web: GUI on http://127.0.0.1:" in output
    assert "[sim_rover]: battery at 80 %" in output  # INFO and above still reach the terminal
    access = ACCESS_LINE.findall(output)
    if verbose:
        assert len(access) >= REQUESTS and "[DEBUG]" in output
    else:
        assert access == [] and "[DEBUG]" not in output
