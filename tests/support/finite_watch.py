"""Test-side handle on tests/support/peers/finite_watch.py: every float a node publishes, checked."""

from __future__ import annotations

import json
import subprocess
import sys
import threading

from rover_web.config import ROOT
from tests.support.rospeer import stop_piped, subprocess_env


class FiniteWatch:
    """tests/support/peers/finite_watch.py: subscribes to every topic the app's node publishes."""

    def __init__(self, prefix: str):
        self.proc = subprocess.Popen([sys.executable, str(ROOT / "tests/support/peers/finite_watch.py"), prefix],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     env=subprocess_env(), cwd=ROOT)
        self.topics: list[str] = []
        self.report: dict | None = None
        self.nonfinite: list[str] = []
        self._changed = threading.Condition()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        for line in self.proc.stdout:
            try:
                event = json.loads(line)
            except ValueError:
                continue  # Fast DDS's own diagnostics share the peer's stdout
            with self._changed:
                if event["event"] == "watching":
                    self.topics = event["topics"]
                elif event["event"] == "nonfinite":
                    self.nonfinite.extend(event["found"])
                elif event["event"] == "report":
                    self.report = event
                self._changed.notify_all()

    def wait_watching(self, *topics: str, timeout: float = 20.0) -> None:
        with self._changed:
            if not self._changed.wait_for(lambda: set(topics) <= set(self.topics), timeout):
                raise AssertionError(f"the watch never subscribed to {topics}; it has {self.topics}")

    def wait_nonfinite(self, count: int, timeout: float = 10.0) -> list[str]:
        with self._changed:
            if not self._changed.wait_for(lambda: len(self.nonfinite) >= count, timeout):
                raise AssertionError(f"the watch reported {self.nonfinite}, not {count} non-finite values")
            return list(self.nonfinite)

    def finish(self) -> dict:
        self.proc.stdin.write("quit\n")
        self.proc.stdin.flush()
        self._reader.join(15)
        stop_piped(self.proc, "quit")
        assert self.report is not None, "the watch sent no report"
        return self.report
