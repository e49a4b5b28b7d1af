"""`flask --app rover_web users|tokens|tls ...` in a real process, with no ROS node started."""

import sqlite3
import subprocess
import sys

import pytest

from rover_web.config import ROOT
from tests.support.rospeer import subprocess_env


def flask(tmp_path, *args, stdin=None):
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "cli.sqlite3"))
    return subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", *args], env=env, cwd=tmp_path,
                          input=stdin, capture_output=True, text=True, timeout=60)


def test_users_add_list_set_role_remove(tmp_path):
    added = flask(tmp_path, "users", "add", "ada", "--role", "operator", "--password-stdin",
                  stdin="correct horse battery\n")
    assert added.returncode == 0, added.stderr
    listed = flask(tmp_path, "users", "list")
    assert "ada\toperator" in listed.stdout
    assert flask(tmp_path, "users", "set-role", "ada", "admin").returncode == 0
    assert "ada\tadmin" in flask(tmp_path, "users", "list").stdout
    with sqlite3.connect(tmp_path / "cli.sqlite3") as conn:
        stored = conn.execute("SELECT password_hash FROM auth_users").fetchone()[0]
    assert "correct horse" not in stored and stored.startswith("$argon2id$")
    assert flask(tmp_path, "users", "remove", "ada").returncode == 0
    assert "no users" in flask(tmp_path, "users", "list").stdout


def test_users_add_refuses_a_bad_role_a_short_password_and_a_duplicate(tmp_path):
    assert flask(tmp_path, "users", "add", "ada", "--role", "root", "--password-stdin", stdin="x" * 12).returncode != 0
    short = flask(tmp_path, "users", "add", "ada", "--role", "viewer", "--password-stdin", stdin="short\n")
    assert short.returncode != 0 and "8" in short.stderr
    assert flask(tmp_path, "users", "add", "ada", "--role", "viewer", "--password-stdin",
                 stdin="long enough\n").returncode == 0
    again = flask(tmp_path, "users", "add", "ada", "--role", "admin", "--password-stdin", stdin="long enough\n")
    assert again.returncode != 0 and "exists" in again.stderr


def test_tokens_are_printed_once_and_revocable(tmp_path):
    flask(tmp_path, "users", "add", "bot", "--role", "operator", "--password-stdin", stdin="long enough\n")
    created = flask(tmp_path, "tokens", "create", "bot", "--label", "mission script")
    assert created.returncode == 0, created.stderr
    token = created.stdout.strip()
    assert token.startswith("rwt_") and len(token) > 40
    listed = flask(tmp_path, "tokens", "list").stdout
    assert "bot\tactive\tmission script" in listed and token not in listed
    token_id = listed.split("\t")[0]
    assert flask(tmp_path, "tokens", "revoke", token_id).returncode == 0
    assert "revoked" in flask(tmp_path, "tokens", "list").stdout


def test_tls_self_signed_writes_a_pair_and_says_how_to_use_it(tmp_path):
    made = flask(tmp_path, "tls", "self-signed", "--host", "robot.local", "--dir", str(tmp_path / "tls"))
    assert made.returncode == 0, made.stderr
    assert f"ROVER_WEB_TLS_CERT={tmp_path / 'tls' / 'cert.pem'}" in made.stdout
    assert (tmp_path / "tls" / "key.pem").is_file()


@pytest.mark.parametrize("args", [["users", "list"], ["tokens", "list"], ["--help"]])
def test_cli_commands_work_without_ros(tmp_path, args):
    """They never start a ROS node: they work even where rclpy cannot be imported."""
    broken = tmp_path / "no_ros" / "rclpy"
    broken.mkdir(parents=True)
    (broken / "__init__.py").write_text("raise ImportError('no ROS on this machine')\n")
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "cli.sqlite3"))
    env["PYTHONPATH"] = f"{broken.parent}:{env['PYTHONPATH']}"
    result = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", *args], env=env, cwd=ROOT,
                            capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    if args == ["--help"]:
        assert all(group in result.stdout for group in ("users", "tokens", "tls"))
