"""Test-side handle on tests/peers/image_publisher.py: a camera in another process."""

from __future__ import annotations

import json
import subprocess
import sys
import time

from tests.support.rospeer import ROOT, stop_piped, subprocess_env


class ImagePublisher:
    def __init__(self, topic: str, width: int = 320, height: int = 240, hz: float = 30.0, qos: str = "default",
                 grain: int = 0):
        self.topic = topic
        self.proc = subprocess.Popen(
            [sys.executable, str(ROOT / "tests" / "support" / "peers" / "image_publisher.py"), "--topic", topic,
             "--width", str(width), "--height", str(height), "--hz", str(hz), "--qos", qos, "--grain", str(grain)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=subprocess_env(), cwd=ROOT)
        reply = self._reply()
        if reply.get("event") != "ready":
            self.close()
            raise RuntimeError(f"image publisher did not start: {reply!r}")

    def _reply(self) -> dict:
        """The peer's next JSON line. Fast DDS writes its own diagnostics to the same stdout (a shared
        memory port another process holds, on a busy machine), so lines that are not JSON are skipped."""
        for line in self.proc.stdout:
            try:
                return json.loads(line)
            except json.JSONDecodeError:
                continue
        return {}  # the peer exited

    def status(self) -> dict:
        """{"published": frames so far, "subscribers": matched subscriptions}, with when it was asked."""
        asked = time.monotonic()
        self.proc.stdin.write("status\n")
        self.proc.stdin.flush()
        reply = self._reply()
        reply["t"] = (asked + time.monotonic()) / 2
        return reply

    def close(self) -> None:
        stop_piped(self.proc, "quit")
