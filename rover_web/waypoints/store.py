"""The mission: an ordered list of GPS waypoints kept in SQLite. Pure Python, no Flask, no rclpy.

Every change runs in a transaction (BEGIN IMMEDIATE ... COMMIT with synchronous=FULL; concurrent
changes share one, see storage/group_commit.py, each in its own savepoint) and a method returns only
after that commit, so a change the caller acknowledges is on disk, and a crash leaves either the
whole change or none of it.
The table's CHECK constraints repeat the input rules, so even a bug cannot store a waypoint the
robot must not receive (NaN becomes NULL in SQLite and fails NOT NULL; infinities fail BETWEEN).
Positions are always exactly 0..n-1 (UNIQUE), and a mission revision counts every change so a
client can tell which of two lists is newer and "send" can refuse a list the operator never saw.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from rover_web.storage.group_commit import GroupCommitter
from rover_web.web.validate import InvalidInput

MAX_LABEL_CHARS = 80

SCHEMA = """
CREATE TABLE IF NOT EXISTS waypoints (
    id         INTEGER PRIMARY KEY AUTOINCREMENT,
    position   INTEGER NOT NULL UNIQUE CHECK (typeof(position) = 'integer' AND position >= 0),
    lng        REAL    NOT NULL CHECK (typeof(lng) = 'real' AND lng BETWEEN -180.0 AND 180.0),
    lat        REAL    NOT NULL CHECK (typeof(lat) = 'real' AND lat BETWEEN -90.0 AND 90.0),
    label      TEXT    NOT NULL DEFAULT '' CHECK (typeof(label) = 'text' AND length(label) <= 80),
    created_at REAL    NOT NULL CHECK (created_at > 0)
);
CREATE TABLE IF NOT EXISTS waypoints_meta (
    id       INTEGER PRIMARY KEY CHECK (id = 1),
    revision INTEGER NOT NULL CHECK (typeof(revision) = 'integer' AND revision >= 0)
);
INSERT OR IGNORE INTO waypoints_meta (id, revision) VALUES (1, 0)
"""

# Renumbering moves rows out of the way first: SQLite checks UNIQUE row by row during an UPDATE,
# so "position = position - 1" could collide half way. Shifted positions are >= this offset.
_SHIFT = 1 << 40


class MissionFull(Exception):
    """Adding would exceed the configured maximum number of waypoints."""


class WaypointNotFound(LookupError):
    pass


class StaleRevision(Exception):
    """The client acted on a mission that has changed since it read it."""


class EmptyMission(Exception):
    """There is no waypoint to send."""


@dataclass(frozen=True)
class Waypoint:
    id: int
    index: int
    lng: float
    lat: float
    label: str = ""

    def to_dict(self) -> dict:
        return {"id": self.id, "index": self.index, "lng": self.lng, "lat": self.lat, "label": self.label}


@dataclass(frozen=True)
class Mission:
    revision: int
    waypoints: tuple[Waypoint, ...]

    def to_dict(self) -> dict:
        return {"revision": self.revision, "count": len(self.waypoints),
                "waypoints": [w.to_dict() for w in self.waypoints]}


# --- input rules (shared by every route and the GeoJSON import) ---

def check_lng(value: object, where: str = "lng") -> float:
    return _coordinate(value, where, 180.0)


def check_lat(value: object, where: str = "lat") -> float:
    return _coordinate(value, where, 90.0)


def _coordinate(value: object, where: str, limit: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InvalidInput("'%(where)s' must be a number, got %(type)s", "bad_type",
                           where=where, type=type(value).__name__)
    try:
        number = float(value)
    except OverflowError:  # an integer too large for a float
        raise InvalidInput("'%(where)s' must be between %(value)s and %(limit)s", "out_of_range",
                           where=where, value=format(-limit, "g"), limit=format(limit, "g")) from None
    if not math.isfinite(number):
        raise InvalidInput("'%(where)s' must be finite", "non_finite", where=where)
    if not -limit <= number <= limit:
        raise InvalidInput("'%(where)s' must be between %(value)s and %(limit)s, got %(number)s", "out_of_range",
                           where=where, value=format(-limit, "g"), limit=format(limit, "g"), number=format(number, "g"))
    return number


def check_label(value: object, where: str = "label") -> str:
    if value is None:
        return ""
    if not isinstance(value, str):
        raise InvalidInput("'%(where)s' must be a string, got %(type)s", "bad_type",
                           where=where, type=type(value).__name__)
    if len(value) > MAX_LABEL_CHARS:
        raise InvalidInput("'%(where)s' is longer than %(max_label_chars)s characters", "too_long",
                           where=where, max_label_chars=MAX_LABEL_CHARS)
    if any(ord(c) < 32 or 127 <= ord(c) < 160 or 0xD800 <= ord(c) <= 0xDFFF for c in value):
        raise InvalidInput("'%(where)s' may not contain control characters", "bad_value", where=where)
    return value


def _row(row) -> Waypoint:
    return Waypoint(row["id"], row["position"], row["lng"], row["lat"], row["label"])


class WaypointStore:
    """The stored mission. `db` is a rover_web.storage.db.Database; methods are safe from any thread."""

    def __init__(self, db, max_waypoints: int):
        self.db = db
        self.max_waypoints = max_waypoints
        db.ensure_schema(SCHEMA)
        # Every change goes through one committer thread: concurrent writers share a transaction
        # and its fsync, and each is answered only after that commit (rover_web.storage.group_commit).
        self._committer = GroupCommitter(db, name="waypoints-commit")
        self._commit = self._committer.run

    # --- reads ---

    def mission(self) -> Mission:
        """The list and its revision from one consistent snapshot."""
        conn = self.db.connection()
        conn.execute("BEGIN")
        try:
            revision = conn.execute("SELECT revision FROM waypoints_meta WHERE id = 1").fetchone()[0]
            rows = conn.execute("SELECT id, position, lng, lat, label FROM waypoints ORDER BY position").fetchall()
        finally:
            conn.execute("COMMIT")
        return Mission(revision, tuple(_row(r) for r in rows))

    # --- changes: each bumps the revision, and is committed (fsynced) before the call returns ---

    def add(self, lng: float, lat: float, label: str = "",
            announce: Callable[[Waypoint], None] | None = None) -> tuple[Waypoint, int]:
        """Append a waypoint; returns it and the new revision. MissionFull at the maximum.

        announce(waypoint) runs once it is committed, in mission order even for concurrent adds.
        """
        def change(conn):
            count = self._count(conn)
            if count >= self.max_waypoints:
                raise MissionFull(self.max_waypoints)
            waypoint = self._insert(conn, count, lng, lat, label)
            return waypoint, self._bump(conn)
        after = (lambda result: announce(result[0])) if announce else None
        return self._commit(change, after)

    def update(self, waypoint_id: int, *, lng: float | None = None, lat: float | None = None,
               label: str | None = None, index: int | None = None,
               check: Callable[[float, float], None] | None = None) -> tuple[Waypoint, int]:
        """Move (lng/lat), rename, and/or reorder (index, 0-based; clamped to the list) one waypoint.

        check(lng, lat), when given, sees a moved waypoint's new position inside the transaction and
        may raise to refuse the move (the geofence): nothing is then changed.
        """
        def change(conn):
            row = conn.execute("SELECT id, position, lng, lat, label FROM waypoints WHERE id = ?",
                               (waypoint_id,)).fetchone()
            if row is None:
                raise WaypointNotFound(waypoint_id)
            current = _row(row)
            new_lng = current.lng if lng is None else lng
            new_lat = current.lat if lat is None else lat
            if check is not None and (lng is not None or lat is not None):
                check(new_lng, new_lat)
            conn.execute("UPDATE waypoints SET lng = ?, lat = ?, label = ? WHERE id = ?",
                         (new_lng, new_lat, current.label if label is None else label, waypoint_id))
            if index is not None:
                ids = [r[0] for r in conn.execute("SELECT id FROM waypoints ORDER BY position")]
                ids.remove(waypoint_id)
                ids.insert(max(0, min(index, len(ids))), waypoint_id)
                self._renumber(conn, ids)
            row = conn.execute("SELECT id, position, lng, lat, label FROM waypoints WHERE id = ?",
                               (waypoint_id,)).fetchone()
            return _row(row), self._bump(conn)
        return self._commit(change)

    def delete(self, waypoint_id: int) -> int:
        """Remove one waypoint, closing the gap; returns the new revision."""
        def change(conn):
            row = conn.execute("SELECT position FROM waypoints WHERE id = ?", (waypoint_id,)).fetchone()
            if row is None:
                raise WaypointNotFound(waypoint_id)
            conn.execute("DELETE FROM waypoints WHERE id = ?", (waypoint_id,))
            position = row[0]
            conn.execute("UPDATE waypoints SET position = position + ? WHERE position > ?", (_SHIFT, position))
            conn.execute("UPDATE waypoints SET position = position - ? - 1 WHERE position >= ?", (_SHIFT, _SHIFT))
            return self._bump(conn)
        return self._commit(change)

    def clear(self) -> tuple[int, int]:
        """Remove every waypoint; returns (how many, new revision)."""
        def change(conn):
            deleted = conn.execute("DELETE FROM waypoints").rowcount
            return deleted, self._bump(conn)
        return self._commit(change)

    def replace(self, points: Sequence[tuple[float, float, str]], *, expected_revision: int | None = None) -> Mission:
        """Make `points` (lng, lat, label) the whole mission, in order, atomically (GeoJSON import)."""
        if len(points) > self.max_waypoints:
            raise MissionFull(self.max_waypoints)

        def change(conn):
            if expected_revision is not None:
                self._check_revision(conn, expected_revision)
            conn.execute("DELETE FROM waypoints")
            waypoints = tuple(self._insert(conn, i, lng, lat, label) for i, (lng, lat, label) in enumerate(points))
            return Mission(self._bump(conn), waypoints)
        return self._commit(change)

    def close(self) -> None:
        """Let queued changes commit, then stop the committer thread."""
        self._committer.stop()

    # --- helpers (inside a transaction) ---

    @staticmethod
    def _count(conn) -> int:
        # Positions are 0..n-1, so max+1 is the count without scanning the table.
        return conn.execute("SELECT coalesce(max(position) + 1, 0) FROM waypoints").fetchone()[0]

    @staticmethod
    def _insert(conn, position: int, lng: float, lat: float, label: str) -> Waypoint:
        cursor = conn.execute(
            "INSERT INTO waypoints (position, lng, lat, label, created_at) VALUES (?, ?, ?, ?, ?)",
            (position, float(lng), float(lat), label, time.time()))
        return Waypoint(cursor.lastrowid, position, float(lng), float(lat), label)

    @staticmethod
    def _renumber(conn, ids: Iterable[int]) -> None:
        conn.execute("UPDATE waypoints SET position = position + ?", (_SHIFT,))
        conn.executemany("UPDATE waypoints SET position = ? WHERE id = ?", ((i, wid) for i, wid in enumerate(ids)))

    @staticmethod
    def _bump(conn) -> int:
        return conn.execute(
            "UPDATE waypoints_meta SET revision = revision + 1 WHERE id = 1 RETURNING revision").fetchone()[0]

    @staticmethod
    def _check_revision(conn, expected: int) -> None:
        revision = conn.execute("SELECT revision FROM waypoints_meta WHERE id = 1").fetchone()[0]
        if revision != expected:
            raise StaleRevision(revision)
