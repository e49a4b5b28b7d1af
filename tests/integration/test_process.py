"""The app as an operator runs it: flask run, gunicorn, signals, the reloader, bad settings, no ROS."""

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from tests.support.rospeer import ROOT, subprocess_env

TWIST = "geometry_msgs/msg/Twist"


def is_zero(m):
    return m["linear"]["x"] == 0.0 and m["angular"]["z"] == 0.0


@pytest.mark.parametrize("how", ["flask", "gunicorn"])
def test_sigterm_publishes_zero_twist_then_exits_quickly(how, server_process, ros_peer):
    from tests.conftest import free_port

    port = free_port()
    args = None
    if how == "gunicorn":
        args = [sys.executable, "-m", "gunicorn", "-c", "gunicorn.conf.py", "rover_web:create_app()"]
    server = server_process(port=port, env={"ROVER_WEB_PORT": str(port)}, args=args).start()
    peer = ros_peer()
    peer.subscribe("/cmd_vel", TWIST)
    peer.wait_match("/cmd_vel")
    time.sleep(0.3)  # let the server's side of the match settle too
    sent = time.monotonic()
    server.proc.send_signal(signal.SIGTERM)
    zero = peer.wait_for("/cmd_vel", is_zero, timeout=5)
    code = server.proc.wait(10)
    exited = time.monotonic()
    assert zero["t"] >= sent
    assert exited - sent < 5.0, server.log()
    assert code == 0, server.log()
    assert "Traceback" not in server.log()


def test_ctrl_c_also_stops_the_robot_first(server_process, ros_peer):
    server = server_process().start()
    peer = ros_peer()
    peer.subscribe("/cmd_vel", TWIST)
    peer.wait_match("/cmd_vel")
    time.sleep(0.3)
    server.proc.send_signal(signal.SIGINT)
    peer.wait_for("/cmd_vel", is_zero, timeout=5)
    assert server.proc.wait(10) in (0, 130), server.log()


def node_names(peer):
    return [n for n in peer.graph()["nodes"] if n.endswith("/rover_web")]


def test_reloader_creates_exactly_one_node(server_process, ros_peer):
    from tests.conftest import free_port

    port = free_port()
    server = server_process(port=port, args=[
        sys.executable, "-m", "flask", "--app", "rover_web", "run", "--reload", "--host", "127.0.0.1",
        "--port", str(port)]).start()
    peer = ros_peer()
    deadline = time.monotonic() + 10
    while not node_names(peer):
        assert time.monotonic() < deadline, "no rover_web node appeared"
        time.sleep(0.2)
    time.sleep(2.0)  # a second node would have been discovered by now
    assert node_names(peer) == ["/rover_web"]
    assert "reloader watcher process" in server.log()
    server.stop()


def run_flask(env: dict, timeout=20) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                           "--port", "1"], cwd=ROOT, env=subprocess_env(**env), capture_output=True,
                          text=True, timeout=timeout)


def test_bad_setting_fails_fast_naming_the_key():
    started = time.monotonic()
    result = run_flask({"ROVER_WEB_MAX_LINEAR_MPS": "fast"})
    assert result.returncode != 0
    assert time.monotonic() - started < 15
    last_line = result.stderr.strip().splitlines()[-1]
    assert last_line.startswith("rover_web: ROVER_WEB_MAX_LINEAR_MPS: expected a number"), result.stderr
    assert "Traceback" not in result.stderr


def test_missing_ros_exits_with_one_sentence_on_how_to_install(tmp_path):
    shadow = tmp_path / "rclpy"
    shadow.mkdir()
    (shadow / "__init__.py").write_text("raise ImportError('No module named rclpy')\n")
    env = subprocess_env()
    env["PYTHONPATH"] = f"{tmp_path}{os.pathsep}{env['PYTHONPATH']}"
    result = subprocess.run([sys.executable, "-m", "flask", "--app", "rover_web", "run", "--no-reload",
                             "--port", "1"], cwd=ROOT, env=env, capture_output=True, text=True, timeout=20)
    assert result.returncode != 0
    last_line = result.stderr.strip().splitlines()[-1]
    assert "pip install -e '.[ros]'" in last_line and "/opt/ros/jazzy/setup.bash" in last_line
    assert "Traceback" not in result.stderr


def test_a_served_app_keeps_its_start_up_heap_out_of_the_collector(tmp_path):
    """A full collection over everything start-up built takes ~20 ms, a pause every thread (a
    joystick frame, an SSE delivery) waits out; a served app freezes that heap, a test app does not."""
    script = (
        "import gc, json\n"
        "from rover_web import create_app\n"
        "import os\n"
        "test_app = create_app({'TESTING': True, 'ROVER_WEB_DB_PATH': os.environ['ROVER_WEB_DB_PATH'] + '.test'})\n"
        "testing = gc.get_freeze_count()\n"
        "served_app = create_app()\n"
        "served = gc.get_freeze_count()\n"
        "print(json.dumps({'testing': testing, 'served': served, 'objects': len(gc.get_objects())}))\n"
        # Stopped before the interpreter exits: leaving two apps' ROS threads running into its
        # teardown aborted it once in CI ('terminate called without an active exception').
        "for app in (served_app, test_app):\n"
        "    app.extensions['rover_web'].shutdown()\n"
    )
    env = subprocess_env(ROVER_WEB_DB_PATH=str(tmp_path / "db.sqlite3"), ROVER_WEB_HOST="127.0.0.1")
    result = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True, text=True,
                            timeout=60)
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout.strip().splitlines()[-1])
    assert report["testing"] == 0
    assert report["served"] > 10 * report["objects"]  # nearly everything is frozen, little left to scan
