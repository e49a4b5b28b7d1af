"""The fence on disk: one row of the app's SQLite database, replaced whole in one transaction."""

from __future__ import annotations

import json
import time

SCHEMA = """
CREATE TABLE IF NOT EXISTS geofence (
    id         INTEGER PRIMARY KEY CHECK (id = 1),
    doc        TEXT    NOT NULL CHECK (json_valid(doc)),
    revision   INTEGER NOT NULL CHECK (typeof(revision) = 'integer' AND revision >= 1),
    updated_at REAL    NOT NULL
)
"""


class GeofenceStore:
    def __init__(self, db):
        self._db = db
        db.ensure_schema(SCHEMA)

    def load(self) -> tuple[dict, int] | None:
        """(the stored FeatureCollection, its revision), or None when no fence was ever stored."""
        row = self._db.connection().execute("SELECT doc, revision FROM geofence WHERE id = 1").fetchone()
        return None if row is None else (json.loads(row["doc"]), row["revision"])

    def save(self, doc: dict) -> int:
        """Replace the fence; returns the new revision once it is committed."""
        with self._db.transaction() as conn:
            return conn.execute(
                "INSERT INTO geofence (id, doc, revision, updated_at) VALUES (1, ?, 1, ?) "
                "ON CONFLICT(id) DO UPDATE SET doc = excluded.doc, revision = revision + 1, "
                "updated_at = excluded.updated_at RETURNING revision",
                (json.dumps(doc, separators=(",", ":")), time.time())).fetchone()[0]
