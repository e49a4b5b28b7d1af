"""The database holds password hashes: it, its -wal and -shm are 0600 and a folder made for it
0700, whatever the umask lets through (issue 27: all were created 0644)."""

import logging
import os
import stat

import pytest
from flask import Flask

from rover_web.storage.db import Database, database_path


def mode(path) -> int:
    return stat.S_IMODE(os.stat(path).st_mode)


@pytest.fixture
def permissive_umask():
    old = os.umask(0o022)  # the usual default: files 0644, folders 0755
    yield
    os.umask(old)


def test_a_new_database_its_wal_and_shm_and_its_new_folder_are_private(tmp_path, permissive_umask):
    app = Flask(__name__, instance_path=str(tmp_path / "instance"))
    app.config["ROVER_WEB_DB_PATH"] = str(tmp_path / "made" / "rover_web.sqlite3")
    path = database_path(app)
    assert mode(path.parent) == 0o700
    db = Database(path)
    try:
        with db.transaction() as conn:  # a write in WAL mode: SQLite makes -wal and -shm
            conn.execute("CREATE TABLE secrets (x TEXT)")
            conn.execute("INSERT INTO secrets VALUES ('hash')")
        files = [path, path.with_name(path.name + "-wal"), path.with_name(path.name + "-shm")]
        assert all(f.exists() for f in files)
        assert {str(f): mode(f) for f in files} == {str(f): 0o600 for f in files}
        assert db.connection().execute("SELECT x FROM secrets").fetchone()[0] == "hash"
    finally:
        db.close()


def test_an_existing_folder_keeps_its_mode(tmp_path, permissive_umask):
    folder = tmp_path / "shared"
    folder.mkdir(mode=0o755)
    app = Flask(__name__, instance_path=str(tmp_path / "instance"))
    app.config["ROVER_WEB_DB_PATH"] = str(folder / "db.sqlite3")
    database_path(app)
    assert mode(folder) == 0o755


def test_an_existing_readable_database_is_kept_and_warned_about(tmp_path, permissive_umask, caplog):
    path = tmp_path / "old.sqlite3"
    old = Database(path)
    with old.transaction() as conn:
        conn.execute("CREATE TABLE t (x INTEGER)")
    old.close()
    os.chmod(path, 0o644)
    db = Database(path)
    try:
        with caplog.at_level(logging.WARNING, logger="rover_web.storage.db"):
            db.check()
        assert "may be read by others (mode 644)" in caplog.text
        assert mode(path) == 0o644  # not changed behind the owner's back
    finally:
        db.close()
