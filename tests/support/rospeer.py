"""Test-side handle on tests/peers/peer.py: a real ROS node in another process."""

from __future__ import annotations

import itertools
import json
import os
import queue
import subprocess
import sys
import threading
import time
from collections import defaultdict

from rover_web.config import ROOT


def subprocess_env(**extra: str) -> dict[str, str]:
    """The test process's ROS environment (private domain, localhost only) plus PYTHONPATH."""
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    env["PYTHONUNBUFFERED"] = "1"
    env.update(extra)
    return env


def stop_piped(proc: subprocess.Popen, quit_line: str) -> None:
    """Ask a helper process driven over stdin to quit (kill it if it won't), then close its pipes."""
    if proc.poll() is None:
        try:
            proc.stdin.write(quit_line + "\n")
            proc.stdin.flush()
            proc.wait(5)
        except (OSError, subprocess.TimeoutExpired):
            proc.kill()
            proc.wait(5)
    for stream in (proc.stdin, proc.stdout):
        try:
            stream.close()
        except OSError:
            pass


class RosPeer:
    def __init__(self, name: str = "test_peer"):
        self._ids = itertools.count()
        self.proc = subprocess.Popen([sys.executable, str(ROOT / "tests" / "support" / "peers" / "peer.py"), name],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     env=subprocess_env(), cwd=ROOT)
        self._acks: queue.Queue = queue.Queue()
        self._cond = threading.Condition()
        self.messages: dict[str, list[dict]] = defaultdict(list)
        self.errors: list[str] = []
        self._ready = threading.Event()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        if not self._ready.wait(20):
            self.close()
            raise RuntimeError("ROS peer did not start")

    def _read(self) -> None:
        for line in self.proc.stdout:
            try:
                event = json.loads(line)
            except json.JSONDecodeError:
                continue
            kind = event.get("event")
            if kind == "ready":
                self._ready.set()
            elif kind == "msg":
                with self._cond:
                    self.messages[event["topic"]].append(event)
                    self._cond.notify_all()
            elif kind in ("ack", "error"):
                if kind == "error":
                    self.errors.append(event.get("message", ""))
                self._acks.put(event)

    def _call(self, reply_timeout: float = 15.0, **cmd) -> dict:
        cmd["id"] = next(self._ids)
        self.proc.stdin.write(json.dumps(cmd) + "\n")
        self.proc.stdin.flush()
        reply = self._acks.get(timeout=reply_timeout)
        if reply["event"] == "error":
            raise RuntimeError(f"peer: {reply['message']}")
        return reply

    def subscribe(self, topic: str, type_name: str, qos: str | int = "default", max_items: int = 64) -> None:
        """qos: a profile name (rover_web.ros.qos) or a keep-last depth, for a subscriber that must not
        drop messages while this test process is busy reading them."""
        self._call(op="sub", topic=topic, type=type_name, qos=qos, max_items=max_items)

    def unsubscribe(self, topic: str) -> None:
        self._call(op="unsub", topic=topic)

    def advertise(self, topic: str, type_name: str, qos: str | int = "default") -> None:
        self._call(op="pub", topic=topic, type=type_name, qos=qos)

    def publish(self, topic: str, msg: dict) -> None:
        self._call(op="send", topic=topic, msg=msg)

    def log(self, text: str, level: str = "info", times: int = 1) -> None:
        """Log `text` through the peer node's own logger (to /rosout), `times` times in a row."""
        self._call(op="log", level=level, text=text, times=times)

    def wait_match(self, topic: str, count: int = 1, timeout: float = 10.0) -> None:
        """Block until the peer's publisher or subscription on `topic` sees `count` counterparts."""
        self._call(reply_timeout=timeout + 5, op="wait_match", topic=topic, count=count, timeout=timeout)

    def graph(self, count_topics: list[str] = ()) -> dict:
        """Node names, topics with types, and publisher/subscriber counts as this peer sees them."""
        return self._call(op="graph", count=list(count_topics))

    def received(self, topic: str) -> list[dict]:
        with self._cond:
            return list(self.messages[topic])

    def clear(self, topic: str) -> None:
        with self._cond:
            self.messages[topic].clear()

    def wait_for(self, topic: str, predicate=lambda m: True, timeout: float = 10.0) -> dict:
        """The first message on `topic` (already received or coming) for which predicate(msg) holds."""
        deadline = time.monotonic() + timeout
        with self._cond:
            seen = 0
            while True:
                batch = self.messages[topic]
                for event in batch[seen:]:
                    if predicate(event["msg"]):
                        return event
                seen = len(batch)
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError(f"no matching message on {topic} within {timeout} s "
                                       f"({len(batch)} received)")
                self._cond.wait(remaining)

    def close(self) -> None:
        stop_piped(self.proc, json.dumps({"op": "quit"}))

    def __enter__(self) -> RosPeer:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
