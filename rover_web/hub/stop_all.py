"""The hub's stop-all: a signed stop to each robot's queryable, every robot at once, each answer kept.

One Zenoh get per robot (the command is signed for that robot, so it cannot be one wildcard get),
each on its own thread so that a silent robot costs the others nothing: the whole stop-all takes
about the slowest answer, at most ROVER_WEB_FLEET_STOP_TIMEOUT_S. A robot that does not answer in
time is `no_answer`; an answer that is not the robot's own signed reply to this command is
`bad_answer` (and not believed).
"""

from __future__ import annotations

import json
import logging
import threading
import time
from concurrent.futures import ThreadPoolExecutor

from rover_web.zenoh_link import signing
from rover_web.zenoh_link.session import stop_key

log = logging.getLogger(__name__)

MAX_THREADS = 128  # robots asked at once; beyond it they queue (a fleet that big waits a bound per 128)


class StopAll:
    def __init__(self, session, key: bytes, fleet: str, timeout_s: float):
        self.session, self.key, self.fleet, self.timeout_s = session, key, fleet, timeout_s
        self._lock = threading.Lock()
        self.last: dict | None = None  # the last stop-all's answers, for the page

    def stop(self, names: list[str], by: str) -> dict:
        started = time.time()
        t0 = time.monotonic()
        answers: dict[str, dict] = {}
        if names:
            with ThreadPoolExecutor(max_workers=min(len(names), MAX_THREADS), thread_name_prefix="hub-stop") as pool:
                futures = {name: pool.submit(self.stop_one, name, by) for name in names}
            answers = {name: future.result() for name, future in futures.items()}
        result = {"at": started, "by": by, "took_s": round(time.monotonic() - t0, 3),
                  "engaged": bool(answers) and all(a["result"] == "engaged" for a in answers.values()),
                  "robots": answers}
        with self._lock:
            self.last = result
        log.warning("hub: stop-all by %s: %s", by, ", ".join(f"{n} {a['result']}" for n, a in answers.items()) or
                    "no robot known")
        return result

    def stop_one(self, name: str, by: str) -> dict:
        command = signing.stop_command(self.key, self.fleet, name, by)
        try:
            replies = self.session.get(stop_key(self.fleet, name), payload=json.dumps(command).encode(),
                                       timeout=self.timeout_s)
            for reply in replies:
                if reply.ok is None:
                    continue  # an error reply: keep waiting for the robot's own
                return self._believe(command, reply.ok.payload.to_bytes())
        except Exception as exc:
            log.exception("hub: the stop to %s failed", name)
            return {"result": "error", "message": str(exc)}
        return {"result": "no_answer", "message": f"no answer within {self.timeout_s:g} s"}

    def _believe(self, command: dict, payload: bytes) -> dict:
        try:
            reply = json.loads(payload) if len(payload) <= signing.COMMAND_MAX_BYTES else None
        except ValueError:
            reply = None
        if not signing.answer_checks(self.key, command, reply):
            return {"result": "bad_answer", "message": "the answer does not check with the fleet key"}
        return {k: v for k, v in reply.items() if k in ("result", "reason", "message", "estop")}
