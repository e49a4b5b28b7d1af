"""Group commit: many writers' changes in one SQLite transaction, one fsync, each acknowledged after it.

With synchronous=FULL every COMMIT waits for the disk. Writers hand their change (a function of
the connection) to one committer thread, which runs everything queued in a single transaction,
each change inside its own SAVEPOINT (so one refused change rolls back alone), COMMITs once, and
only then wakes each writer with its result. Nobody is told "done" before the commit that holds
their change is on disk, so an acknowledged write is never lost; under load one fsync carries
many writes instead of one each.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable
from typing import Any

log = logging.getLogger(__name__)

MAX_BATCH = 64


class CommitterStopped(RuntimeError):
    """The committer is shut down; the change was not applied."""


class _Change:
    __slots__ = ("fn", "after_commit", "done", "result", "error")

    def __init__(self, fn: Callable[[Any], Any], after_commit: Callable[[Any], None] | None):
        self.fn = fn
        self.after_commit = after_commit
        self.done = threading.Event()
        self.result: Any = None
        self.error: BaseException | None = None


class GroupCommitter:
    def __init__(self, db, name: str = "group-commit"):
        self._db = db
        self._queue: queue.SimpleQueue[_Change | None] = queue.SimpleQueue()
        self._stopped = False
        self._lock = threading.Lock()
        self.batches = 0  # for tests and benchmarks: how many transactions carried the changes
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def run(self, fn: Callable[[Any], Any], after_commit: Callable[[Any], None] | None = None) -> Any:
        """Apply fn(conn) in a committed transaction; its result, or the exception it raised.

        after_commit(result), if given, runs on the committer thread once the change is on disk,
        in commit order across all writers (so announcements come in the order of the data).
        """
        change = _Change(fn, after_commit)
        with self._lock:
            if self._stopped:
                raise CommitterStopped("the database is shutting down")
            self._queue.put(change)
        change.done.wait()
        if change.error is not None:
            raise change.error
        return change.result

    def _run(self) -> None:
        while True:
            first = self._queue.get()
            if first is None:
                break
            batch = [first]
            stop = False
            while len(batch) < MAX_BATCH:
                try:
                    item = self._queue.get_nowait()
                except queue.Empty:
                    break
                if item is None:
                    stop = True
                    break
                batch.append(item)
            self._commit(batch)
            if stop:
                break
        self._fail_pending()

    def _commit(self, batch: list[_Change]) -> None:
        try:
            with self._db.transaction() as conn:
                for change in batch:
                    conn.execute("SAVEPOINT change")
                    try:
                        change.result = change.fn(conn)
                    except Exception as exc:  # this change only: the others in the batch go on
                        conn.execute("ROLLBACK TO change")
                        change.error = exc
                    conn.execute("RELEASE change")
        except Exception as exc:  # BEGIN or COMMIT failed: nothing in the batch was written
            log.error("group commit of %d changes failed: %s", len(batch), exc)
            for change in batch:
                change.error = exc
                change.result = None
        self.batches += 1
        for change in batch:
            if change.error is None and change.after_commit is not None:
                try:
                    change.after_commit(change.result)
                except Exception as exc:  # stored, but not announced: the writer must hear of it
                    log.exception("after-commit action failed")
                    change.error = exc
            change.done.set()

    def _fail_pending(self) -> None:
        while True:
            try:
                item = self._queue.get_nowait()
            except queue.Empty:
                return
            if item is not None:
                item.error = CommitterStopped("the database is shutting down")
                item.done.set()

    def stop(self, timeout_s: float = 5.0) -> None:
        """Finish what is queued, then stop; later calls to run() raise CommitterStopped."""
        with self._lock:
            if self._stopped:
                return
            self._stopped = True
            self._queue.put(None)
        self._thread.join(timeout_s)
