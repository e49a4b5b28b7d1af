"""Each robot's history on the hub, in its SQLite database: what an operator asks after the fact
("when did the boat drop off, who stopped it, did it answer the stop-all?").

Events: found, waiting, live, lost, forgotten (the directory's sweep); estop_engaged and
estop_released with who (seen in the robot's summaries); stop_all with the robot's answer and the
hub user who asked. Bounded by age (ROVER_WEB_HUB_HISTORY_DAYS) and by count per robot
(ROVER_WEB_HUB_HISTORY_MAX_ROWS), pruned as rows are added; read newest first, a page at a time,
with the id of the last row seen as the cursor (stable while rows are added, unlike an offset).
"""

from __future__ import annotations

import json
import threading
import time

from rover_web.storage.db import Database
from rover_web.storage.migrate import migrate

EVENTS = ("found", "waiting", "live", "lost", "forgotten", "estop_engaged", "estop_released", "stop_all")
PAGE_MAX = 200

STEPS = [
    """CREATE TABLE hub_history (
           id INTEGER PRIMARY KEY AUTOINCREMENT,
           robot TEXT NOT NULL,
           at REAL NOT NULL,
           event TEXT NOT NULL,
           detail TEXT NOT NULL DEFAULT '{}');
       CREATE INDEX hub_history_robot ON hub_history (robot, id)""",
]


class History:
    def __init__(self, db: Database, max_age_s: float, max_rows: int, clock=time.time):
        self.db, self.max_age_s, self.max_rows, self._clock = db, max_age_s, max_rows, clock
        migrate(db, "hub_history", STEPS)
        self._pruned_at = 0.0
        self._lock = threading.Lock()

    def record(self, events: list[tuple[str, str, dict]]) -> None:
        """Append events (robot, event, detail) in one transaction, then keep within the bounds."""
        if not events:
            return
        now = self._clock()
        rows = [(robot, now, event, json.dumps(detail, separators=(",", ":"), sort_keys=True))
                for robot, event, detail in events]
        with self.db.transaction() as conn:
            conn.executemany("INSERT INTO hub_history (robot, at, event, detail) VALUES (?, ?, ?, ?)", rows)
            for robot in {r[0] for r in rows}:
                # Rows past the newest max_rows of this robot: one indexed range delete.
                conn.execute("DELETE FROM hub_history WHERE robot = ? AND id <= (SELECT id FROM hub_history "
                             "WHERE robot = ? ORDER BY id DESC LIMIT 1 OFFSET ?)", (robot, robot, self.max_rows))
            if now - self._pruned_at > 60:
                conn.execute("DELETE FROM hub_history WHERE at < ?", (now - self.max_age_s,))
                self._pruned_at = now

    def page(self, robot: str, *, before: int | None = None, limit: int = 50) -> dict:
        """Newest first: up to `limit` rows older than the row `before` (an id), within the age bound."""
        limit = max(1, min(limit, PAGE_MAX))
        cutoff = self._clock() - self.max_age_s
        conn = self.db.connection()
        rows = conn.execute(
            "SELECT id, at, event, detail FROM hub_history WHERE robot = ? AND at >= ? AND id < ? "
            "ORDER BY id DESC LIMIT ?", (robot, cutoff, before if before is not None else 2**62, limit + 1)).fetchall()
        more = len(rows) > limit
        rows = rows[:limit]
        return {"robot": robot,
                "events": [{"id": r["id"], "at": r["at"], "event": r["event"], "detail": json.loads(r["detail"])}
                           for r in rows],
                "next_before": rows[-1]["id"] if more else None}

    def known(self, robot: str) -> bool:
        row = self.db.connection().execute("SELECT 1 FROM hub_history WHERE robot = ? LIMIT 1", (robot,)).fetchone()
        return row is not None
