"""The latest diagnostic status per name, its age and staleness, the worst level per hardware id. Pure Python.

Ages use the monotonic clock of arrival, not the message stamp: a robot whose clock is off (or a
simulator on sim time) must not make every status look stale or fresh.
"""

from __future__ import annotations

import threading
import time

OK, WARN, ERROR, STALE = 0, 1, 2, 3
LEVEL_NAMES = {OK: "OK", WARN: "WARN", ERROR: "ERROR", STALE: "STALE"}


def level_name(level: int) -> str:
    return LEVEL_NAMES.get(level, str(level))


class DiagnosticsBoard:
    def __init__(self, stale_s: float, clock=time.monotonic, max_names: int = 2000):
        self.stale_s = stale_s
        self._clock = clock
        self._max_names = max_names  # a publisher inventing names must not grow memory without end
        self._latest: dict[str, tuple[float, dict]] = {}
        self._lock = threading.Lock()

    def update(self, statuses: list[dict], source: str) -> None:
        now = self._clock()
        with self._lock:
            for status in statuses:
                name = status["name"]
                if name not in self._latest and len(self._latest) >= self._max_names:
                    continue
                self._latest[name] = (now, {**status, "source": source})

    def __len__(self) -> int:
        with self._lock:
            return len(self._latest)

    def snapshot(self, now: float | None = None) -> list[dict]:
        """Every status by name, with `age_s` and `stale`; a stale one keeps its last level."""
        now = self._clock() if now is None else now
        with self._lock:
            items = sorted(self._latest.items())
        out = []
        for _, (received, status) in items:
            age = max(0.0, now - received)
            out.append({**status, "level_name": level_name(status["level"]), "age_s": round(age, 3),
                        "stale": age > self.stale_s})
        return out

    @staticmethod
    def worst_by_hardware(statuses: list[dict]) -> list[dict]:
        """One row per hardware id: its worst level (stale counts as STALE, worse than ERROR)."""
        worst: dict[str, dict] = {}
        for status in statuses:
            level = STALE if status["stale"] else status["level"]
            key = status["hardware_id"] or status["name"]
            row = worst.setdefault(key, {"hardware_id": key, "level": level, "names": []})
            row["names"].append(status["name"])
            row["level"] = max(row["level"], level)
        for row in worst.values():
            row["level_name"] = level_name(row["level"])
        return sorted(worst.values(), key=lambda r: (-r["level"], r["hardware_id"]))
