"""Numbered schema changes for a package's tables, applied once each, in order, at start.

`ensure_schema` (db.py) suits tables that never change; a package whose tables will change lists
its steps here instead: `migrate(db, "layouts", [STEP_1, STEP_2])`. Applied steps are counted in
`schema_versions` (one row per package), in the same transaction as the step, so a crash mid-way
leaves either the old schema or the new one, never half of it. A step is never edited once
released: a change is a new step at the end.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from sqlite3 import Connection

from rover_web.config import ConfigError

from .db import Database

VERSIONS_DDL = "CREATE TABLE IF NOT EXISTS schema_versions (package TEXT PRIMARY KEY, version INTEGER NOT NULL)"

Step = str | Callable[[Connection], None]


def migrate(db: Database, package: str, steps: Sequence[Step]) -> int:
    """Apply the steps of `package` not applied yet; returns how many were applied now.

    A step is DDL (statements separated by ';') or a function given the open transaction."""
    db.ensure_schema(VERSIONS_DDL)
    with db.transaction() as conn:
        row = conn.execute("SELECT version FROM schema_versions WHERE package = ?", (package,)).fetchone()
        done = row["version"] if row else 0
        if done > len(steps):
            raise ConfigError(f"the database's {package} tables are at version {done}, newer than this "
                               f"rover_web knows ({len(steps)}): use a newer rover_web or another database")
        for step in steps[done:]:
            if callable(step):
                step(conn)
            else:
                for statement in step.split(";"):
                    if statement.strip():
                        conn.execute(statement)
        conn.execute("INSERT INTO schema_versions (package, version) VALUES (?, ?) "
                      "ON CONFLICT(package) DO UPDATE SET version = excluded.version", (package, len(steps)))
    return len(steps) - done
