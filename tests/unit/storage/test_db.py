"""rover_web.db: per-thread connections do not outlive their threads."""

import gc
import threading

import psutil

from rover_web.storage.db import Database


def open_db_files(path) -> int:
    return sum(1 for f in psutil.Process().open_files() if f.path == str(path))


def test_a_threads_connection_is_closed_when_the_thread_ends(tmp_path):
    """`flask run` serves every request on a new thread; their connections must not pile up."""
    path = tmp_path / "threads.sqlite3"
    db = Database(path)
    try:
        with db.transaction() as conn:
            conn.execute("CREATE TABLE t (x INTEGER)")
        baseline = open_db_files(path)

        def request():
            with db.transaction() as conn:
                conn.execute("INSERT INTO t VALUES (1)")

        def serve(requests: int) -> int:
            for _ in range(requests):
                thread = threading.Thread(target=request)
                thread.start()
                thread.join()
            gc.collect()
            return open_db_files(path)

        # SQLite may keep one closed connection's descriptor for reuse (POSIX lock rules); it must
        # not grow with the number of threads that came and went.
        after_a_few = serve(5)
        assert after_a_few <= baseline + 1
        assert serve(35) == after_a_few
        assert db.connection().execute("SELECT count(*) FROM t").fetchone()[0] == 40
    finally:
        db.close()
    assert open_db_files(path) == 0
