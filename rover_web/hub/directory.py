"""Every robot the hub hears on Zenoh: its latest authentic summary, and whether it is still there.

A robot is `live` while its liveliness token is declared and its last summary is younger than
ROVER_WEB_FLEET_LOST_AFTER_S; else `lost`. Either sign alone marks it lost: the token goes at
once when the robot's process or its link ends (Zenoh closes its sessions' tokens), and the
summaries stop when the robot's app hangs while its Zenoh session lives on.

Summaries whose HMAC does not check under the fleet key are counted and dropped; so is one not
newer (by the robot's own `sent` time) than the last accepted, so a recorded summary played
again cannot show an old state. Liveliness tokens carry no signature: a forged token makes a
robot look present only until its summaries are missed, and a robot needs an authentic summary
to be listed as live at all.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from rover_web.zenoh_link import signing
from rover_web.zenoh_link.session import ROOT_KEY, robot_of

log = logging.getLogger(__name__)

# What /api/robots gives for a robot whose token was heard but no authentic summary yet.
UNHEARD = {"namespace": None, "kind": "robot", "url": None, "link": "no_data", "mode": None, "operator": None,
           "speed": None, "battery": None, "estop": {"engaged": None, "since": None, "by": None},
           "position": None, "alerts": []}


def web_url(url: object) -> str | None:
    """The robot's URL if it is one a page may link to: http(s) only, never javascript: or data:."""
    if isinstance(url, str) and url.lower().startswith(("http://", "https://")) and len(url) <= 2000:
        return url
    return None


class _Heard:
    def __init__(self, name: str):
        self.name = name
        self.summary: dict | None = None
        self.sent = float("-inf")  # the robot's clock, for ordering its summaries
        self.received: float | None = None  # the hub's monotonic clock
        self.alive = False


class Directory:
    def __init__(self, key: bytes, fleet: str, lost_after_s: float, clock: Callable[[], float] = time.monotonic):
        self.key, self.fleet = key, fleet
        self.lost_after_s = lost_after_s
        self.forged = 0  # summaries dropped: a bad signature, or another robot's name in the key
        self._clock = clock
        self._robots: dict[str, _Heard] = {}
        self._lock = threading.Lock()
        self._declared: list = []

    def listen(self, session) -> None:
        """Subscribe to every robot's summary and token; history: the tokens declared before we came."""
        self._declared = [
            session.declare_subscriber(f"{ROOT_KEY}/{self.fleet}/*/summary", self._on_summary),
            session.liveliness().declare_subscriber(f"{ROOT_KEY}/{self.fleet}/*/alive", self._on_alive, history=True),
        ]

    def close(self) -> None:
        for declared in self._declared:
            try:
                declared.undeclare()
            except Exception:
                log.exception("hub: could not undeclare a subscriber")
        self._declared = []

    # --- from Zenoh's threads ---

    def _on_summary(self, sample) -> None:
        self.summary_arrived(str(sample.key_expr), sample.payload.to_bytes())

    def summary_arrived(self, key_expr: str, payload: bytes) -> bool:
        opened = signing.open_summary(self.key, self.fleet, payload)
        name = robot_of(key_expr)
        if opened is None or opened["robot"] != name:
            with self._lock:
                self.forged += 1
            if self.forged in (1, 10) or self.forged % 1000 == 0:
                log.warning("hub: dropped %d summaries that did not check with the fleet key (latest on %s)",
                            self.forged, key_expr)
            return False
        with self._lock:
            heard = self._robots.setdefault(name, _Heard(name))
            if not isinstance(opened["sent"], (int, float)) or opened["sent"] <= heard.sent:
                return False  # an old one, replayed or overtaken
            heard.summary, heard.sent, heard.received = opened["summary"], opened["sent"], self._clock()
        return True

    def _on_alive(self, sample) -> None:
        name = robot_of(sample.key_expr)
        if not name:
            return
        alive = str(sample.kind).endswith("PUT")
        with self._lock:
            self._robots.setdefault(name, _Heard(name)).alive = alive
        log.info("hub: robot %s %s", name, "present" if alive else "gone (its liveliness token ended)")

    # --- for the routes ---

    def names(self) -> list[str]:
        with self._lock:
            return sorted(self._robots)

    def robots(self) -> list[dict]:
        """Each robot's summary in GET /api/robots's shape, plus how the hub hears it."""
        now = self._clock()
        lines = []
        with self._lock:
            heard_all = sorted(self._robots.values(), key=lambda h: h.name)
            for heard in heard_all:
                age = None if heard.received is None else now - heard.received
                live = heard.alive and age is not None and age <= self.lost_after_s
                line = {**UNHEARD, "title": heard.name, **(heard.summary or {}), "name": heard.name,
                        "heard": "live" if live else "lost", "alive": heard.alive,
                        "summary_age_s": None if age is None else round(age, 3)}
                line["url"] = web_url(line.get("url"))
                lines.append(line)
        return lines
