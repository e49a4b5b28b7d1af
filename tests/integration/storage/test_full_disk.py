"""A full disk under the database: writes get 507 JSON, the server keeps serving and driving, and the
file passes its integrity check with every acknowledged write in it (issue 21)."""

import os
import sqlite3
import subprocess
import uuid

import pytest
import requests

from tests.support.waiting import wait_until

MAX_LINEAR = 2.5  # the default ROVER_WEB_MAX_LINEAR_MPS: "forward" at full scale


@pytest.fixture
def small_disk(tmp_path):
    """A 3 MiB tmpfs: real ENOSPC from the kernel, not a mocked error."""
    mount = tmp_path / "disk"
    mount.mkdir()
    made = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=3m", "tmpfs", str(mount)], capture_output=True)
    if made.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs here: {made.stderr.decode().strip()}")
    yield mount
    subprocess.run(["umount", "-l", str(mount)], check=False)


def fill(folder, leave_bytes: int = 0) -> None:
    """Fill the file system until the kernel says it is full, then free `leave_bytes`."""
    filler = folder / "filler"
    with open(filler, "wb") as f:
        chunk = b"\0" * 65536
        try:
            while True:
                f.write(chunk)
                f.flush()
        except OSError:
            pass
    if leave_bytes:
        os.truncate(filler, max(0, filler.stat().st_size - leave_bytes))


def test_a_full_disk_gets_507_and_the_server_keeps_serving_and_driving(server_process, small_disk, ros_peer):
    db = small_disk / "robot.sqlite3"
    server = server_process(env={"ROVER_WEB_DB_PATH": str(db), "ROVER_WEB_MAX_WAYPOINTS": "100000",
                                 "ROVER_WEB_PANEL_REFUSALS_PER_MIN": "10000"}).start()
    url = server.url
    peer = ros_peer("full_disk_listener")
    peer.subscribe("/cmd_vel", "geometry_msgs/msg/Twist")
    peer.wait_match("/cmd_vel")

    acked = []

    def add(i):
        body = {"lat": 27.0 + i * 1e-6, "lng": -82.0, "label": f"w{i}-{uuid.uuid4().hex[:8]}"}
        r = requests.post(url + "/api/waypoints", json=body, timeout=10)
        if r.ok:
            acked.append(body["label"])
        return r

    for i in range(5):
        assert add(i).status_code in (200, 201)
    fill(small_disk)

    statuses = []
    for i in range(5, 400):
        r = add(i)
        statuses.append(r.status_code)
        assert r.status_code < 500 or r.status_code in (503, 507), (r.status_code, r.text)
        assert r.headers["Content-Type"].startswith("application/json")
        if r.status_code == 507:
            assert r.json()["error"] == "disk_full" and r.json()["message"]
            break
    assert 507 in statuses, statuses[-5:]

    # Still serving, and still driving: motion never waits on the disk.
    assert requests.get(url + "/api/status", timeout=5).status_code == 200
    assert requests.get(url + "/api/waypoints", timeout=5).status_code == 200
    assert requests.post(url + "/api/teleop", json={"command": "forward"}, timeout=5).status_code == 200
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] > 0, timeout=3.0)
    # A panel command whose operator-log line cannot be written is still answered (refused: locked).
    assert requests.post(url + "/api/panels/drone/takeoff", json={"confirmed": True}, timeout=5).status_code == 409
    # The e-stop engages on a full disk (its latch is written after stopping, and may fail).
    engaged = requests.post(url + "/api/estop", json={"engaged": True}, timeout=5)
    assert engaged.status_code == 200 and engaged.json()["engaged"] is True
    peer.wait_for("/cmd_vel", lambda m: m["linear"]["x"] == 0.0, timeout=3.0)

    # Space again: writes work again without a restart.
    os.unlink(small_disk / "filler")
    requests.post(url + "/api/estop", json={"engaged": False}, timeout=5)
    wait_until(lambda: add(1000).ok, 10, "a write succeeds once space is back")

    server.stop()
    conn = sqlite3.connect(db)
    try:
        assert conn.execute("PRAGMA integrity_check").fetchall() == [("ok",)]
        names = {row[0] for row in conn.execute("SELECT label FROM waypoints")}
    finally:
        conn.close()
    missing = [name for name in acked if name not in names]
    assert not missing, f"{len(missing)} acknowledged waypoints lost, e.g. {missing[:3]}"
