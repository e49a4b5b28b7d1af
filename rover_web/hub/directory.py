"""Every robot the hub hears on Zenoh: its latest authentic summary, and where it stands.

A robot is, in `heard`:
- `waiting`: its liveliness token is there and no summary came since (it has just started, or the
  hub has); for at most ROVER_WEB_FLEET_LOST_AFTER_S, after which it is `lost`: a token that is
  never followed by an authentic summary (a forged one, a robot with another key) is not a robot;
- `live`: its token is there and its last authentic, fresh summary is younger than
  ROVER_WEB_FLEET_LOST_AFTER_S;
- `lost`: otherwise. Either sign alone marks it lost: the token goes at once when the robot's
  process or its link ends (Zenoh closes its sessions' tokens), and the summaries stop when the
  robot's app hangs while its Zenoh session lives on.
A robot `lost` for ROVER_WEB_FLEET_FORGET_AFTER_S is forgotten: dropped from the list, named
among the recently forgotten, counted, and written in the history (hub/history.py).

What is believed (issue 40): a summary is opened only when its size is within bounds and its
HMAC checks over its raw bytes (zenoh_link/signing.py), before any JSON parser sees it; one whose
`sent` is further from the hub's clock than ROVER_WEB_FLEET_COMMAND_WINDOW_S is refused (a
recorded summary played again after a hub restart showed a robot long gone as live); and one not
newer (by the robot's own `sent` time) than the last accepted is dropped, so a summary played
again within the window cannot show an old state either. Liveliness tokens carry no signature:
a token alone makes a robot `waiting`, never `live`, and the number of names kept is bounded.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable

from rover_web.zenoh_link import signing
from rover_web.zenoh_link.session import NAME, ROOT_KEY, robot_of

log = logging.getLogger(__name__)

# What /api/robots gives for a robot whose token was heard but no authentic summary yet.
UNHEARD = {"namespace": None, "kind": "robot", "url": None, "link": "no_data", "mode": None, "operator": None,
           "speed": None, "battery": None, "estop": {"engaged": None, "since": None, "by": None},
           "position": None, "alerts": []}
STATES = ("waiting", "live", "lost")
MAX_ROBOTS = 1000  # names kept: tokens are unsigned, so a flood of made-up names must not grow the hub
RECENTLY_FORGOTTEN = 20


def web_url(url: object) -> str | None:
    """The robot's URL if it is one a page may link to: http(s) only, never javascript: or data:."""
    if isinstance(url, str) and url.lower().startswith(("http://", "https://")) and len(url) <= 2000:
        return url
    return None


class _Heard:
    def __init__(self, name: str, now: float):
        self.name = name
        self.summary: dict | None = None
        self.sent = float("-inf")  # the robot's clock, for ordering its summaries
        self.received: float | None = None  # the hub's monotonic clock
        self.alive = False
        self.alive_since = now  # when its token last came (monotonic)
        self.state: str | None = None  # as last swept, for the history
        self.since = now  # when it entered that state (monotonic)


class Directory:
    def __init__(self, key: bytes, fleet: str, lost_after_s: float, *, window_s: float = 10.0,
                 forget_after_s: float = 3600.0, clock: Callable[[], float] = time.monotonic,
                 wall: Callable[[], float] = time.time):
        self.key, self.fleet = key, fleet
        self.lost_after_s, self.window_s, self.forget_after_s = lost_after_s, window_s, forget_after_s
        # Summaries dropped, by why: forged (bad signature, another robot's name in the key, or
        # oversized), stale (outside the clock window).
        self.forged = 0
        self.stale = 0
        self.forgotten_total = 0
        self.forgotten: deque[dict] = deque(maxlen=RECENTLY_FORGOTTEN)
        self._clock, self._wall = clock, wall
        self._robots: dict[str, _Heard] = {}
        self._events: list[tuple[str, str, dict]] = []  # (robot, event, detail) for the history, taken by sweep
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
        payload = sample.payload
        # Refused before it is even copied out of Zenoh's buffer when it is too big to be a summary.
        if len(payload) > signing.SUMMARY_MAX_BYTES:
            self._dropped(str(sample.key_expr))
            return
        self.summary_arrived(str(sample.key_expr), payload.to_bytes())

    def _dropped(self, key_expr: str) -> None:
        with self._lock:
            self.forged += 1
            forged = self.forged
        if forged in (1, 10) or forged % 1000 == 0:
            log.warning("hub: dropped %d summaries that did not check with the fleet key (latest on %s)",
                        forged, key_expr)

    def summary_arrived(self, key_expr: str, payload: bytes) -> bool:
        name = robot_of(key_expr)
        opened = signing.open_summary(self.key, self.fleet, payload)
        if opened is None or opened["robot"] != name:
            self._dropped(key_expr)
            return False
        sent = opened["sent"]
        skew = self._wall() - sent
        if not math.isfinite(skew) or abs(skew) > self.window_s:
            with self._lock:
                self.stale += 1
                stale = self.stale
            if stale in (1, 10) or stale % 1000 == 0:
                log.warning("hub: refused %d summaries sent outside the clock window (latest from %s, %+.0f s)",
                            stale, name, skew)
            return False
        with self._lock:
            heard = self._get(name)
            if heard is None or sent <= heard.sent:
                return False  # an old one, replayed or overtaken
            self._note_estop(heard, opened["summary"])
            heard.summary, heard.sent, heard.received = opened["summary"], sent, self._clock()
            self._moved(heard, heard.received)
        return True

    def _on_alive(self, sample) -> None:
        name = robot_of(sample.key_expr)
        if not name:
            return
        alive = str(sample.kind).endswith("PUT")
        with self._lock:
            heard = self._get(name)
            if heard is None:
                return
            now = self._clock()
            if alive and not heard.alive:
                heard.alive_since = now
            heard.alive = alive
            self._moved(heard, now)
        log.info("hub: robot %s %s", name, "present" if alive else "gone (its liveliness token ended)")

    def _get(self, name: str) -> _Heard | None:
        """The robot's entry, made on first hearing (within MAX_ROBOTS); called with the lock held."""
        heard = self._robots.get(name)
        if heard is None:
            # A robot's name is a-z 0-9 _ (zenoh_link/session.py): a token under another is nobody's,
            # and never becomes a page's text or a metric's label.
            if len(self._robots) >= MAX_ROBOTS or not NAME.match(name):
                return None
            heard = self._robots[name] = _Heard(name, self._clock())
            self._events.append((name, "found", {}))
        return heard

    def _note_estop(self, heard: _Heard, summary: dict) -> None:
        estop = summary.get("estop") if isinstance(summary.get("estop"), dict) else {}
        before = (heard.summary or {}).get("estop") if isinstance((heard.summary or {}).get("estop"), dict) else {}
        engaged = estop.get("engaged")
        if isinstance(engaged, bool) and engaged != before.get("engaged") and (heard.summary or engaged):
            by = estop.get("by") if isinstance(estop.get("by"), str) else None
            self._events.append((heard.name, "estop_engaged" if engaged else "estop_released",
                                 {"by": by[:80] if by else None}))

    # --- the hub's sweep (a background loop) and its routes ---

    def _state(self, heard: _Heard, now: float) -> str:
        if heard.alive and heard.received is not None and now - heard.received <= self.lost_after_s:
            return "live"
        if heard.alive and (heard.received is None or heard.received < heard.alive_since) \
                and now - heard.alive_since <= self.lost_after_s:
            return "waiting"
        return "lost"

    def _moved(self, heard: _Heard, now: float) -> bool:
        """Note a change of state for the history; called with the lock held, on each arrival (a
        state may last less than a sweep: waiting for 50 ms) and by the sweep (for the timeouts)."""
        state = self._state(heard, now)
        if state == heard.state:
            return False
        heard.state, heard.since = state, now
        self._events.append((heard.name, state, {}))
        return True

    def sweep(self) -> list[tuple[str, str, dict]]:
        """Each robot's state brought up to date: the changes (and what arrived meanwhile) for the
        history; robots lost for ROVER_WEB_FLEET_FORGET_AFTER_S forgotten."""
        now = self._clock()
        with self._lock:
            for heard in list(self._robots.values()):
                if not self._moved(heard, now) and heard.state == "lost" \
                        and now - heard.since >= self.forget_after_s:
                    del self._robots[heard.name]
                    self.forgotten_total += 1
                    self.forgotten.appendleft({"name": heard.name, "at": round(self._wall(), 3)})
                    self._events.append((heard.name, "forgotten", {"lost_for_s": round(now - heard.since)}))
                    log.info("hub: forgot robot %s, lost for %.0f s", heard.name, now - heard.since)
            events, self._events = self._events, []
        return events

    def names(self) -> list[str]:
        with self._lock:
            return sorted(self._robots)

    def counts(self) -> dict[str, int]:
        """Robots in each state, for /api/status and /metrics."""
        now = self._clock()
        counts = dict.fromkeys(STATES, 0)
        with self._lock:
            for heard in self._robots.values():
                counts[self._state(heard, now)] += 1
        return counts

    def robots(self) -> list[dict]:
        """Each robot's summary in GET /api/robots's shape, plus how the hub hears it."""
        now = self._clock()
        lines = []
        with self._lock:
            heard_all = sorted(self._robots.values(), key=lambda h: h.name)
            for heard in heard_all:
                age = None if heard.received is None else now - heard.received
                state = self._state(heard, now)
                line = {**UNHEARD, "title": heard.name, **(heard.summary or {}), "name": heard.name,
                        "heard": state, "alive": heard.alive,
                        "summary_age_s": None if age is None else round(age, 3),
                        "forget_in_s": None}
                if state == "lost":  # swept as lost already, or about to be at the next sweep
                    lost_for = now - heard.since if heard.state == "lost" else 0.0
                    line["forget_in_s"] = round(max(0.0, self.forget_after_s - lost_for))
                line["url"] = web_url(line.get("url"))
                lines.append(line)
        return lines

    def recently_forgotten(self) -> list[dict]:
        with self._lock:
            return list(self.forgotten)
