"""The recordings' index: one SQLite row per MCAP file, so the list survives restarts.

The file is the recording; the row is what the list shows without opening it (name, topics,
counts, why it stopped). A row whose file is gone is forgotten at start; a row left `recording` by
a process that died is marked `interrupted` (its file is readable up to its last flushed chunk).
"""

from __future__ import annotations

import json
from pathlib import Path

SCHEMA = """
CREATE TABLE IF NOT EXISTS recordings (
    id          TEXT PRIMARY KEY CHECK (length(id) BETWEEN 1 AND 64),
    robot       TEXT NOT NULL,
    name        TEXT NOT NULL DEFAULT '',
    file        TEXT NOT NULL,
    started_at  REAL NOT NULL,
    ended_at    REAL,
    state       TEXT NOT NULL CHECK (state IN ('recording', 'stopped', 'interrupted')),
    stop_reason TEXT,
    error       TEXT,
    started_by  TEXT NOT NULL DEFAULT '',
    stopped_by  TEXT,
    selection   TEXT NOT NULL DEFAULT '',
    topics      TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(topics)),
    counts      TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(counts)),
    dropped     TEXT NOT NULL DEFAULT '{}' CHECK (json_valid(dropped)),
    size        INTEGER NOT NULL DEFAULT 0
)
"""

_JSON = ("topics", "counts", "dropped")


class RecordingIndex:
    def __init__(self, db):
        self._db = db
        db.ensure_schema(SCHEMA)

    def add(self, row: dict) -> None:
        values = {k: json.dumps(v) if k in _JSON else v for k, v in row.items()}
        names = ", ".join(values)
        with self._db.transaction() as conn:
            conn.execute(f"INSERT INTO recordings ({names}) VALUES ({', '.join('?' * len(values))})",
                         tuple(values.values()))

    def update(self, recording_id: str, **fields) -> None:
        values = {k: json.dumps(v) if k in _JSON else v for k, v in fields.items()}
        assignments = ", ".join(f"{k} = ?" for k in values)
        with self._db.transaction() as conn:
            conn.execute(f"UPDATE recordings SET {assignments} WHERE id = ?", (*values.values(), recording_id))

    def get(self, recording_id: str) -> dict | None:
        row = self._db.connection().execute("SELECT * FROM recordings WHERE id = ?", (recording_id,)).fetchone()
        return None if row is None else _decoded(row)

    def all(self, robot: str) -> list[dict]:
        rows = self._db.connection().execute(
            "SELECT * FROM recordings WHERE robot = ? ORDER BY started_at DESC", (robot,)).fetchall()
        return [_decoded(row) for row in rows]

    def delete(self, recording_id: str) -> None:
        with self._db.transaction() as conn:
            conn.execute("DELETE FROM recordings WHERE id = ?", (recording_id,))

    def reconcile(self, folder: Path, robot: str) -> None:
        """At start: forget rows whose file is gone; a row still `recording` was cut by a crash."""
        for row in self.all(robot):
            path = folder / row["file"]
            if not path.exists():
                self.delete(row["id"])
            elif row["state"] == "recording":
                self.update(row["id"], state="interrupted", stop_reason="interrupted", size=path.stat().st_size,
                            ended_at=row["ended_at"] or path.stat().st_mtime)


def _decoded(row) -> dict:
    return {k: json.loads(row[k]) if k in _JSON else row[k] for k in row.keys()}
