"""The operator log: every command sent or refused, and every unlock and lock, kept in SQLite."""

from __future__ import annotations

import json
import time
from datetime import UTC, datetime
from typing import Any

RESULTS = ("sent", "refused", "invalid", "unlocked", "locked")

SCHEMA = """
CREATE TABLE IF NOT EXISTS panel_log (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    t REAL NOT NULL CHECK (t > 0),
    panel TEXT NOT NULL CHECK (length(panel) BETWEEN 1 AND 32),
    control TEXT NOT NULL CHECK (length(control) BETWEEN 1 AND 64),
    label TEXT NOT NULL,
    value TEXT,
    result TEXT NOT NULL CHECK (result IN ('sent', 'refused', 'invalid', 'unlocked', 'locked')),
    reason TEXT NOT NULL DEFAULT '',
    client TEXT NOT NULL DEFAULT ''
);
CREATE INDEX IF NOT EXISTS panel_log_by_panel ON panel_log (panel, id)
"""

MAX_VALUE_TEXT = 120


def value_text(value: Any) -> str | None:
    """The value as JSON, cut short: a refused request may carry anything."""
    if value is None:
        return None
    try:
        text = json.dumps(value, allow_nan=False)
    except (TypeError, ValueError):
        text = json.dumps(repr(value))
    return text if len(text) <= MAX_VALUE_TEXT else text[:MAX_VALUE_TEXT - 1] + "…"


def _decoded(text: str | None) -> Any:
    if text is None or text.endswith("…"):
        return None
    try:
        return json.loads(text)
    except ValueError:
        return None


def entry_dict(row) -> dict:
    t = row["t"]
    return {
        "id": row["id"],
        "t": t,
        "time": datetime.fromtimestamp(t, UTC).isoformat(timespec="milliseconds"),
        "clock": datetime.fromtimestamp(t).strftime("%H:%M:%S"),  # the server's local time, as operators read it
        "panel": row["panel"],
        "control": row["control"],
        "label": row["label"],
        "value": _decoded(row["value"]),  # null when it was cut short; value_text has what was kept
        "value_text": row["value"] or "",
        "result": row["result"],
        "reason": row["reason"],
        "client": row["client"],
    }


class OperatorLog:
    def __init__(self, db, keep: int, audit=None):
        self._db = db
        self._keep = keep
        self._audit = audit  # the robot's AuditHub (events/audit.py): each entry goes to recordings too
        db.ensure_schema(SCHEMA)

    def record(self, panel: str, control: str, label: str, value: Any, result: str, reason: str = "",
               client: str = "") -> dict:
        """Write one entry (committed before returning) and return it as the API shows it."""
        if self._audit is not None:  # first: a disk that fails the write below must not hide the action
            self._audit.record(f"{panel}.{result}", by=client, detail=f"{label}: {result}"
                               + (f" ({reason})" if reason else ""), control=control, value=value_text(value))
        t = time.time()
        with self._db.transaction() as conn:
            cursor = conn.execute(
                "INSERT INTO panel_log (t, panel, control, label, value, result, reason, client) "
                "VALUES (?, ?, ?, ?, ?, ?, ?, ?)",
                (t, panel, control[:64], label[:200], value_text(value), result, reason[:500], client[:64]))
            entry_id = cursor.lastrowid
            # Keep the newest `keep` entries of this panel; the (panel, id) index keeps this cheap.
            conn.execute("DELETE FROM panel_log WHERE panel = ? AND id < (SELECT id FROM panel_log WHERE panel = ? "
                         "ORDER BY id DESC LIMIT 1 OFFSET ?)", (panel, panel, self._keep - 1))
            row = conn.execute("SELECT * FROM panel_log WHERE id = ?", (entry_id,)).fetchone()
        return entry_dict(row)

    def recent(self, panel: str, limit: int) -> list[dict]:
        """Newest first."""
        rows = self._db.connection().execute(
            "SELECT * FROM panel_log WHERE panel = ? ORDER BY id DESC LIMIT ?", (panel, limit)).fetchall()
        return [entry_dict(row) for row in rows]
