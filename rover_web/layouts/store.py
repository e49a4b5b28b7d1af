"""Layouts in the robot's SQLite database (each robot of a fleet has its own file), and each user's choice.

Tables (storage/migrate.py, package "layouts"):
  layouts        id, name (unique, any case), the layout JSON, the robot kind it is the default of
                 (NULL for a team's own), when and by whom it last changed
  layout_choice  the layout each user picked; the user "" is everyone while sign-in is off
The defaults (defaults.py) are written in the step that creates the tables: the first start only,
so a default a team deleted does not come back.
"""

from __future__ import annotations

import json
import sqlite3
import time

from rover_web.storage.db import Database
from rover_web.storage.migrate import migrate

from .defaults import DEFAULTS

SHARED = ""  # the choice made while sign-in is off: one for every browser

CREATE = """
CREATE TABLE layouts (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    name TEXT NOT NULL COLLATE NOCASE UNIQUE CHECK (length(name) <= 60),
    body TEXT NOT NULL,
    kind TEXT,
    updated_at REAL NOT NULL,
    updated_by TEXT NOT NULL DEFAULT ''
);
CREATE TABLE layout_choice (
    user TEXT PRIMARY KEY,
    layout_id INTEGER NOT NULL REFERENCES layouts(id) ON DELETE CASCADE
)
"""


def _seed(conn: sqlite3.Connection) -> None:
    for kind, doc in DEFAULTS.items():
        conn.execute("INSERT INTO layouts (name, body, kind, updated_at, updated_by) VALUES (?, ?, ?, ?, ?)",
                     (doc["name"], json.dumps(doc), kind, time.time(), "first start"))


STEPS = [CREATE, _seed]


class NameTaken(ValueError):
    pass


def _storable(layout_id: int) -> bool:
    """An id SQLite can hold: a larger one (a URL or body may carry any integer) is no layout, not a 500."""
    return 0 < layout_id < 2**63


class LayoutStore:
    def __init__(self, db: Database, kind: str):
        self._db = db
        self.kind = kind
        migrate(db, "layouts", STEPS)

    def list(self) -> list[dict]:
        rows = self._db.connection().execute(
            "SELECT id, name, body, kind, updated_at, updated_by FROM layouts ORDER BY id").fetchall()
        return [{"id": r["id"], "name": r["name"], "kind": r["kind"], "cards": len(json.loads(r["body"])["cards"]),
                 "updated_at": r["updated_at"], "updated_by": r["updated_by"]} for r in rows]

    def get(self, layout_id: int) -> dict | None:
        if not _storable(layout_id):
            return None
        row = self._db.connection().execute("SELECT body FROM layouts WHERE id = ?", (layout_id,)).fetchone()
        return json.loads(row["body"]) if row else None

    def add(self, doc: dict, by: str) -> int:
        try:
            with self._db.transaction() as conn:
                cur = conn.execute("INSERT INTO layouts (name, body, updated_at, updated_by) VALUES (?, ?, ?, ?)",
                                   (doc["name"], json.dumps(doc), time.time(), by))
                return int(cur.lastrowid)
        except sqlite3.IntegrityError:
            raise NameTaken(doc["name"]) from None

    def replace(self, layout_id: int, doc: dict, by: str) -> bool:
        if not _storable(layout_id):
            return False
        try:
            with self._db.transaction() as conn:
                cur = conn.execute("UPDATE layouts SET name = ?, body = ?, updated_at = ?, updated_by = ? "
                                   "WHERE id = ?", (doc["name"], json.dumps(doc), time.time(), by, layout_id))
                return cur.rowcount == 1
        except sqlite3.IntegrityError:
            raise NameTaken(doc["name"]) from None

    def delete(self, layout_id: int) -> bool:
        if not _storable(layout_id):
            return False
        with self._db.transaction() as conn:  # the users who had chosen it fall back (active)
            return conn.execute("DELETE FROM layouts WHERE id = ?", (layout_id,)).rowcount == 1

    def choose(self, user: str, layout_id: int) -> bool:
        if not _storable(layout_id):
            return False
        with self._db.transaction() as conn:
            if conn.execute("SELECT 1 FROM layouts WHERE id = ?", (layout_id,)).fetchone() is None:
                return False
            conn.execute("INSERT INTO layout_choice (user, layout_id) VALUES (?, ?) "
                         "ON CONFLICT(user) DO UPDATE SET layout_id = excluded.layout_id", (user, layout_id))
            return True

    def active(self, user: str | None) -> tuple[int | None, dict]:
        """The layout `user` sees: their choice, else the one chosen while sign-in was off, else the
        default of this robot's kind, else the oldest there is; with none left, the built-in default
        of the kind, unsaved (id None)."""
        conn = self._db.connection()
        for who in ([user] if user else []) + [SHARED]:
            row = conn.execute("SELECT l.id, l.body FROM layout_choice c JOIN layouts l ON l.id = c.layout_id "
                               "WHERE c.user = ?", (who,)).fetchone()
            if row:
                return row["id"], json.loads(row["body"])
        row = conn.execute("SELECT id, body FROM layouts ORDER BY kind IS NOT ?, id LIMIT 1", (self.kind,)).fetchone()
        if row:
            return row["id"], json.loads(row["body"])
        return None, DEFAULTS.get(self.kind, DEFAULTS["robot"])
