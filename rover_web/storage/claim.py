"""One server per database: the e-stop latch, panel locks and teleop lease live in the server's
memory and are only mirrored to SQLite, so two servers on one file would each hold their own and
disagree about whether the robot may move.

The claim is an exclusive `flock` on a file beside the database, held for the server's life and
dropped by the kernel when the process ends however it ends (SIGKILL included), so a crash never
leaves a stale claim. A lock on the database file itself would not do: SQLite's own POSIX locks on
it are dropped when any descriptor of that file in the process is closed. The CLI (`flask users`,
`flask tokens`) does not claim: it may run beside the server.
"""

from __future__ import annotations

import fcntl
import os
from pathlib import Path

from rover_web.config import ConfigError


class DatabaseClaim:
    def __init__(self, fd: int, path: Path):
        self._fd: int | None = fd
        self.path = path

    def release(self) -> None:
        if self._fd is not None:
            os.close(self._fd)  # closing drops the flock
            self._fd = None


def claim(database: Path) -> DatabaseClaim:
    """Claim `database` for this process; ConfigError naming the file if another server has it."""
    lock_path = database.with_name(database.name + ".server-lock")
    try:
        fd = os.open(lock_path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o600)
    except OSError as exc:
        raise ConfigError(f"cannot claim the database {database}: {lock_path} cannot be opened for writing "
                          f"({exc.strerror}); the server needs a writable folder for its database") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "unknown"
        os.close(fd)
        raise ConfigError(
            f"another rover_web server (pid {holder}) is already using the database {database}; each "
            f"server keeps its own e-stop latch and panel locks, so two on one database would disagree. "
            f"Stop that server, or give this one its own ROVER_WEB_DB_PATH") from None
    except BaseException:
        os.close(fd)
        raise
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
    return DatabaseClaim(fd, lock_path)
