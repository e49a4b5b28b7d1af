"""The e-stop latch on disk, so a robot stopped by its operator does not come back un-stopped.

One row in the app's SQLite database (rover.db). Engaging is recorded after the robot was stopped
(stopping never waits on a disk); releasing is recorded before motion is allowed again, so a
release that could not be written leaves the e-stop engaged.
"""

from __future__ import annotations

ESTOP_DDL = """
CREATE TABLE IF NOT EXISTS teleop_estop (
    id INTEGER PRIMARY KEY CHECK (id = 1),
    engaged INTEGER NOT NULL CHECK (engaged IN (0, 1)),
    changed_at REAL NOT NULL,
    changed_by TEXT NOT NULL CHECK (length(changed_by) <= 80)
)
"""


class EStopStore:
    def __init__(self, db):
        self._db = db
        db.ensure_schema(ESTOP_DDL)

    def load(self) -> dict:
        row = self._db.connection().execute(
            "SELECT engaged, changed_at, changed_by FROM teleop_estop WHERE id = 1").fetchone()
        if row is None:
            return {"engaged": False, "since": None, "by": None}
        return {"engaged": bool(row["engaged"]), "since": row["changed_at"], "by": row["changed_by"]}

    def save(self, state: dict) -> None:
        with self._db.transaction() as conn:
            conn.execute(
                "INSERT INTO teleop_estop (id, engaged, changed_at, changed_by) VALUES (1, ?, ?, ?) "
                "ON CONFLICT(id) DO UPDATE SET engaged = excluded.engaged, changed_at = excluded.changed_at, "
                "changed_by = excluded.changed_by",
                (1 if state["engaged"] else 0, float(state["since"]), str(state["by"] or "")[:80]))
