"""Test-side handle on tests/support/peers/action_server.py: an action server in another process."""

from __future__ import annotations

import json
import queue
import subprocess
import sys
import threading

from rover_web.config import ROOT
from tests.support.rospeer import stop_piped, subprocess_env


class ActionServerPeer:
    def __init__(self, name: str, cancel_delay_s: float = 0.0):
        self.proc = subprocess.Popen(
            [sys.executable, str(ROOT / "tests" / "support" / "peers" / "action_server.py"), name,
             str(cancel_delay_s)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=subprocess_env(), cwd=ROOT)
        self.events: queue.Queue = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self.wait("ready", 20)

    def _read(self) -> None:
        for line in self.proc.stdout:
            try:
                self.events.put(json.loads(line))
            except ValueError:
                pass

    def wait(self, event: str, timeout: float = 10.0) -> dict:
        while True:
            got = self.events.get(timeout=timeout)
            if got["event"] == event:
                return got

    def send_goal(self) -> dict:
        self.proc.stdin.write("goal\n")
        self.proc.stdin.flush()
        return self.wait("accepted", 15)

    def close(self) -> None:
        stop_piped(self.proc, "quit")


class AdminPeer(ActionServerPeer):
    """tests/support/peers/admin_peer.py: parameters of every type and std_srvs services."""

    def __init__(self, namespace: str = "/peer_ns", name: str = "param_peer"):
        self.proc = subprocess.Popen(
            [sys.executable, str(ROOT / "tests" / "support" / "peers" / "admin_peer.py"), namespace, name],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=subprocess_env(), cwd=ROOT)
        self.events = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()
        self.wait("ready", 20)
