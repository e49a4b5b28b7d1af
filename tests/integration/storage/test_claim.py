"""One server per database: a second server on the same SQLite file refuses to start, naming it."""

import os
import signal
import subprocess
import sys

import pytest

from rover_web.config import ConfigError


def test_a_second_server_on_the_same_database_refuses_to_start_naming_the_file(server_process, tmp_path):
    db = tmp_path / "shared.sqlite3"
    first = server_process(env={"ROVER_WEB_DB_PATH": str(db)}).start()
    second = server_process(env={"ROVER_WEB_DB_PATH": str(db)})
    with pytest.raises(RuntimeError, match="server exited with"):
        second.start(timeout=20)
    assert f"rover_web: another rover_web server (pid {first.proc.pid}) is already using the database {db}" \
        in second.log()
    assert "Traceback" not in second.log()
    # The CLI may still use the claimed file beside its server, and another file is not affected.
    from tests.support.rospeer import subprocess_env

    listed = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "users", "list"],
                            env=subprocess_env(ROVER_WEB_DB_PATH=str(db)), capture_output=True, text=True,
                            timeout=60)
    assert listed.returncode == 0, listed.stderr
    server_process(env={"ROVER_WEB_DB_PATH": str(tmp_path / "other.sqlite3")}).start()


def test_a_killed_server_leaves_no_claim_behind(server_process, tmp_path):
    db = tmp_path / "killed.sqlite3"
    first = server_process(env={"ROVER_WEB_DB_PATH": str(db)}).start()
    first.proc.send_signal(signal.SIGKILL)
    first.proc.wait(10)
    server_process(env={"ROVER_WEB_DB_PATH": str(db)}).start()  # the kernel dropped the lock with the process


def test_in_one_process_the_claim_is_held_until_shutdown(app_factory, tmp_path):
    db = tmp_path / "one.sqlite3"
    app = app_factory(ROVER_WEB_DB_PATH=str(db))
    with pytest.raises(ConfigError, match=str(db)) as refused:
        app_factory(ROVER_WEB_DB_PATH=str(db))
    assert f"pid {os.getpid()}" in str(refused.value)
    app.extensions["rover_web"].shutdown()
    app_factory(ROVER_WEB_DB_PATH=str(db))



def test_a_database_path_that_cannot_be_made_is_a_clear_error_not_a_traceback(server_process, tmp_path):
    blocker = tmp_path / "not_a_folder"
    blocker.write_text("a file where a folder should be")
    server = server_process(env={"ROVER_WEB_DB_PATH": str(blocker / "db.sqlite3")})
    with pytest.raises(RuntimeError, match="server exited with"):
        server.start(timeout=20)
    assert f"rover_web: cannot use the database {blocker / 'db.sqlite3'}" in server.log()
    assert "Traceback" not in server.log()


def test_a_corrupt_database_at_start_is_a_sentence_and_an_exit(server_process, tmp_path):
    db = tmp_path / "corrupt.sqlite3"
    db.write_bytes(os.urandom(16384))
    server = server_process(env={"ROVER_WEB_DB_PATH": str(db)})
    with pytest.raises(RuntimeError, match="server exited with"):
        server.start(timeout=20)
    assert f"rover_web: the database {db} cannot be used: file is not a database; it is not a SQLite " \
        "database, or is damaged; move it aside" in server.log()
    assert "Traceback" not in server.log()


def test_a_read_only_database_at_start_is_a_sentence_and_an_exit(server_process, tmp_path):
    """Root ignores file modes, so the file sits on a tmpfs remounted read-only."""
    mount = tmp_path / "ro"
    mount.mkdir()
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(mount)], capture_output=True)
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")
    try:
        db = mount / "robot.sqlite3"
        first = server_process(env={"ROVER_WEB_DB_PATH": str(db)}).start()  # a real database, with tables
        first.stop()
        subprocess.run(["mount", "-o", "remount,ro", str(mount)], check=True)
        server = server_process(env={"ROVER_WEB_DB_PATH": str(db)})
        with pytest.raises(RuntimeError, match="server exited with"):
            server.start(timeout=20)
        assert f"rover_web: cannot claim the database {db}" in server.log() or \
            f"rover_web: the database {db} cannot be used" in server.log(), server.log()[-800:]
        assert "must be able to write" in server.log() or "writable folder" in server.log()
        assert "Traceback" not in server.log()
    finally:
        subprocess.run(["umount", "-l", str(mount)], check=False)
