"""The app's SQLite database: one file, WAL, full sync, so an acknowledged write survives a crash.

Each feature owns its tables and creates them with `ensure_schema`. Connections are per thread
(sqlite3 objects must not cross threads); a write is committed before the request is answered.

The file holds password hashes: a folder rover_web makes for it is 0700, and the file is created
0600 before SQLite opens it. SQLite gives the `-wal` and `-shm` files it makes beside it the
database file's own mode, so they are 0600 too (without this, all three were 0644).
"""

from __future__ import annotations

import logging
import os
import sqlite3
import stat
import threading
import weakref
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from flask import Flask

from rover_web.config import ConfigError

log = logging.getLogger(__name__)


def database_path(app: Flask) -> Path:
    configured = app.config.get("ROVER_WEB_DB_PATH")
    path = Path(configured) if configured else Path(app.instance_path) / "rover_web.sqlite3"
    try:
        path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)  # the mode only if made here
    except OSError as exc:
        raise ConfigError(f"cannot use the database {path}: its folder cannot be made ({exc.strerror}); "
                          f"set ROVER_WEB_DB_PATH to a file in a writable folder") from None
    return path


class _ThreadConnection:
    """One thread's connection, held in thread-local storage (see Database.connection)."""

    __slots__ = ("conn", "__weakref__")

    def __init__(self, conn: sqlite3.Connection):
        self.conn = conn


class Database:
    def __init__(self, path: str | os.PathLike):
        self.path = str(path)
        self._local = threading.local()
        self._all: set[sqlite3.Connection] = set()
        self._lock = threading.Lock()
        self._write_lock = threading.RLock()
        self._created = False

    def _create_private(self) -> None:
        """Make the file, empty and 0600, if it does not exist (SQLite takes an empty file as a new
        database); an existing one keeps its mode, with a warning if others may read it."""
        try:
            fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        except FileExistsError:
            mode = stat.S_IMODE(os.stat(self.path).st_mode)
            if mode & 0o077:
                log.warning("the database %s (password hashes) may be read by others (mode %o): chmod 600 it",
                            self.path, mode)
            return
        except OSError:
            return  # a folder that cannot be written: SQLite's own error says so, with its hint (check)
        os.close(fd)

    def connection(self) -> sqlite3.Connection:
        holder = getattr(self._local, "holder", None)
        if holder is None:
            with self._lock:
                if not self._created:
                    self._create_private()
                    self._created = True
            conn = sqlite3.connect(self.path, timeout=10.0, isolation_level=None, check_same_thread=False)
            conn.row_factory = sqlite3.Row
            conn.execute("PRAGMA journal_mode=WAL")
            # FULL: a commit is on disk before we answer 2xx, even if power is cut right after.
            conn.execute("PRAGMA synchronous=FULL")
            conn.execute("PRAGMA foreign_keys=ON")
            holder = _ThreadConnection(conn)
            self._local.holder = holder
            with self._lock:
                self._all.add(conn)
            # Werkzeug's server (flask run) runs every request in a new thread. The thread's local
            # data, and so the holder, goes when the thread ends; close its connection then, or
            # each request would leak a connection, its page cache and three file descriptors.
            weakref.finalize(holder, self._forget, conn)
        return holder.conn

    def _forget(self, conn: sqlite3.Connection) -> None:
        with self._lock:
            self._all.discard(conn)
        try:
            conn.close()
        except sqlite3.Error:
            pass

    @contextmanager
    def transaction(self) -> Iterator[sqlite3.Connection]:
        """BEGIN IMMEDIATE ... COMMIT, or ROLLBACK on any exception: never a half-written record."""
        conn = self.connection()
        # Writers of this process queue on a lock, not in SQLite's busy handler: that one retries
        # with sleeps of up to 100 ms, which under 8 concurrent writers gave p99 latencies of 200 ms
        # for 2 ms writes. The lock hands over the moment a commit ends. (Re-entrant only so that a
        # nested call fails with SQLite's clear error instead of deadlocking.)
        with self._write_lock:
            conn.execute("BEGIN IMMEDIATE")
            try:
                yield conn
            except BaseException:
                conn.execute("ROLLBACK")
                raise
            conn.execute("COMMIT")

    def ensure_schema(self, ddl: str) -> None:
        with self.transaction() as conn:
            for statement in ddl.split(";"):
                if statement.strip():
                    conn.execute(statement)

    def check(self) -> None:
        """At start: the file is a sound SQLite database this process can write, or a ConfigError
        that says so and what to do (a traceback from the first request would say neither)."""
        try:
            conn = self.connection()
            problems = [row[0] for row in conn.execute("PRAGMA quick_check").fetchall()]
            if problems != ["ok"]:
                raise ConfigError(f"the database {self.path} is damaged ({'; '.join(problems[:3])}); move it "
                                  f"aside to start with an empty one, or restore a backup")
            with self.transaction() as c:  # a write lock and nothing written: proves it can be written
                c.execute("CREATE TABLE IF NOT EXISTS rover_web_write_check (id INTEGER)")
                c.execute("DROP TABLE rover_web_write_check")
        except sqlite3.Error as exc:
            self.close()
            if "readonly" in str(exc) or "read-only" in str(exc):
                hint = "the server must be able to write it and its folder"
            else:
                hint = "it is not a SQLite database, or is damaged; move it aside to start with an empty one, " \
                       "or restore a backup"
            raise ConfigError(f"the database {self.path} cannot be used: {exc}; {hint}") from None

    def close(self) -> None:
        with self._lock:
            for conn in self._all:
                try:
                    conn.close()
                except sqlite3.Error:
                    pass
            self._all.clear()
        self._local = threading.local()
