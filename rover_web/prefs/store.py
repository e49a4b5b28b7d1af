"""The users' choices in the app's SQLite database (storage/migrate.py, package "prefs").

One row per user who chose something; a column NULL is "not chosen" (the browser's choice, or
the default, applies). The CHECKs keep a value no release understands out of the table.
"""

from __future__ import annotations

import time

from rover_web.storage.db import Database
from rover_web.storage.migrate import migrate

CREATE = """
CREATE TABLE user_preferences (
    user TEXT PRIMARY KEY CHECK (length(user) BETWEEN 1 AND 40),
    theme TEXT CHECK (theme IN ('auto', 'dark', 'daylight')),
    language TEXT CHECK (length(language) <= 16),
    updated_at REAL NOT NULL
)
"""

FIELDS = ("theme", "language")


class PreferenceStore:
    def __init__(self, db: Database):
        self._db = db
        migrate(db, "prefs", [CREATE])

    def get(self, user: str) -> dict:
        row = self._db.connection().execute(
            "SELECT theme, language FROM user_preferences WHERE user = ?", (user,)).fetchone()
        return {k: row[k] for k in FIELDS if row[k] is not None} if row else {}

    def update(self, user: str, changes: dict) -> dict:
        """Set the given fields (a None clears one); returns the user's choices after."""
        with self._db.transaction() as conn:
            row = conn.execute("SELECT theme, language FROM user_preferences WHERE user = ?", (user,)).fetchone()
            now = {k: (row[k] if row else None) for k in FIELDS}
            now.update(changes)
            conn.execute("INSERT INTO user_preferences (user, theme, language, updated_at) VALUES (?, ?, ?, ?) "
                         "ON CONFLICT(user) DO UPDATE SET theme = excluded.theme, language = excluded.language, "
                         "updated_at = excluded.updated_at",
                         (user, now["theme"], now["language"], time.time()))
        return {k: v for k, v in now.items() if v is not None}
