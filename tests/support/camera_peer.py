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
        line = self.proc.stdout.readline()
        if json.loads(line or "{}").get("event") != "ready":
            self.close()
            raise RuntimeError(f"image publisher did not start: {line!r}")

    def status(self) -> dict:
        """{"published": frames so far, "subscribers": matched subscriptions}, with when it was asked."""
        asked = time.monotonic()
        self.proc.stdin.write("status\n")
        self.proc.stdin.flush()
        reply = json.loads(self.proc.stdout.readline())
        reply["t"] = (asked + time.monotonic()) / 2
        return reply

    def close(self) -> None:
        stop_piped(self.proc, "quit")
