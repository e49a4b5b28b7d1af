"""`python -m rover_web.demo` (what scripts/demo.sh runs): GUI + simulator, one Ctrl-C stops both."""

import os
import signal
import subprocess
import sys
import time

import psutil
import requests

from tests.conftest import free_port
from tests.support.rospeer import ROOT, subprocess_env


def test_demo_serves_the_simulated_robot_and_one_ctrl_c_stops_everything(tmp_path):
    port = free_port()
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "demo.sqlite3"))
    # A terminal's Ctrl-C goes to the whole foreground process group: do the same.
    proc = subprocess.Popen([sys.executable, "-m", "rover_web.demo", "--port", str(port)], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        deadline = time.monotonic() + 30
        link = None
        while time.monotonic() < deadline:
            try:
                link = requests.get(f"http://127.0.0.1:{port}/api/status", timeout=1).json()["robot_link"]
                if link == "ok":
                    break
            except requests.RequestException:
                pass
            time.sleep(0.2)
        assert link == "ok", "the GUI never heard the simulated robot"
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
