"""`python -m rover_web.demo` (what scripts/demo.sh runs): GUI + simulator, one Ctrl-C stops both."""

import os
import signal
import subprocess
import sys
import time

import psutil
import pytest
import requests

from tests.conftest import free_port
from tests.support.rospeer import ROOT, subprocess_env


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
