"""Schemathesis against the OpenAPI description, on a real server with the simulator and a topic watch.

Every described operation gets up to MAX_EXAMPLES generated requests (valid and invalid) as an
admin with an API token. It passes when no answer is a 5xx, no message the app published carried
a non-finite float, and the database passes PRAGMA integrity_check afterwards. Operations marked
x-fuzz "last" (those that would stop the rest from being tested: the e-stop, removing users and
tokens) run in a second phase; "skip" ones (endless streams, the WebSocket) are not fuzzed.
"""

from __future__ import annotations

import json
import os
import sqlite3
import subprocess
import sys

import pytest
import requests

from tests.support.auth import add_users
from tests.support.finite_watch import FiniteWatch
from tests.support.rospeer import subprocess_env

pytestmark = pytest.mark.ros

# 20 generated cases per operation in the suite (the coverage phase's boundary values come on top,
# unaffected): 50 took the suite's longest test to two minutes, 30 to 95 s, in a suite that must
# stay under 20 minutes. FUZZ_MAX_EXAMPLES=<n> goes deeper.
MAX_EXAMPLES = int(os.environ.get("FUZZ_MAX_EXAMPLES", "20"))
# Fixed, so a run is repeatable; FUZZ_SEED=<n> in the environment tries other inputs.
SEED = int(os.environ.get("FUZZ_SEED", "16"))
SERVER_SETTINGS = {
    "ROVER_WEB_AUTH": "required",
    "ROVER_WEB_CAMERA_SNAPSHOT_TIMEOUT_S": "0.2",  # a snapshot of a topic nobody publishes waits this long
}


def real_path_values(url: str, headers: dict) -> dict[str, list]:
    maps = requests.get(url + "/api/maps", headers=headers, timeout=5).json()["maps"]
    panels = requests.get(url + "/api/panels", headers=headers, timeout=5).json()["panels"]
    return {"name": [m["name"] for m in maps], "panel_id": [p["id"] for p in panels],
            "control_id": sorted({c["id"] for p in panels for c in p["controls"]} | {"lock", "unlock"})}


def schemathesis_run(url: str, token: str, token_id: int, selection: str, seed: int,
                     workdir) -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "schemathesis.cli", "run", f"{url}/api/openapi.json",
           "--include-by", f"/x-fuzz == {selection}",
           "--checks", "not_a_server_error",
           "--max-examples", str(MAX_EXAMPLES), "--seed", str(seed),
           "--phases", "examples,coverage,fuzzing", "--workers", "1", "--no-shrink",
           "--request-timeout", "20", "--max-redirects", "0",
           "--header", f"Authorization: Bearer {token}",
           "--suppress-health-check", "all", "--warnings", "off"]
    env = subprocess_env(SCHEMATHESIS_HOOKS="tests.support.fuzz_hooks", FUZZ_KEEP_USER="admin",
                         FUZZ_KEEP_TOKEN_ID=str(token_id), NO_COLOR="1", COLUMNS="200",
                         FUZZ_REAL_PATH_VALUES=json.dumps(real_path_values(url, {"Authorization": f"Bearer {token}"})))
    # In the test's folder: Schemathesis keeps a cache (.schemathesis/) where it runs.
    run = subprocess.run(cmd, cwd=workdir, env=env, capture_output=True, text=True, timeout=600)
    print(f"--- schemathesis, x-fuzz {selection} ---\n{run.stdout}\n{run.stderr}")  # shown when the test fails
    return run


def test_fuzzing_every_operation_finds_no_5xx_no_nan_and_a_sound_database(server_process, sim_process, tmp_path):
    db_path = tmp_path / "fuzz.sqlite3"
    token = add_users(db_path, "admin")["admin"]
    with sqlite3.connect(db_path) as db:
        token_id = db.execute("SELECT id FROM auth_tokens WHERE user_name = 'admin'").fetchone()[0]
    sim_process()
    server = server_process(env={**SERVER_SETTINGS, "ROVER_WEB_DB_PATH": str(db_path)}).start()
    watch = FiniteWatch("rover_web")
    try:
        watch.wait_watching("/cmd_vel", "/e_stop")
        document = requests.get(server.url + "/api/openapi.json", headers={"Authorization": f"Bearer {token}"},
                                timeout=5).json()
        selected = {selection: sum(op["x-fuzz"] == selection for item in document["paths"].values()
                                   for op in item.values()) for selection in ("yes", "last")}
        runs = [schemathesis_run(server.url, token, token_id, selection, SEED, tmp_path)
                for selection in ("yes", "last")]
        # The fuzz still had its access at the end, so the second phase was tested as the first.
        me = requests.get(server.url + "/api/me", headers={"Authorization": f"Bearer {token}"}, timeout=5)
        assert me.status_code == 200 and me.json()["role"] == "admin"
    finally:
        report = watch.finish()
        server.stop()
    for run, count in zip(runs, selected.values(), strict=True):
        assert run.returncode == 0, f"{run.stdout[-12000:]}\n{run.stderr[-3000:]}\nserver log:\n{server.log()[-6000:]}"
        assert f"Tested: {count}\n" in run.stdout, run.stdout[-3000:]  # every selected operation was called
    assert "unhandled error" not in server.log()
    assert report["nonfinite"] == [], report["nonfinite"]
    assert report["counts"].get("/cmd_vel", 0) > 0, report["counts"]  # the watch heard the app
    print("topics watched:", watch.topics, "messages:", report["counts"])
    with sqlite3.connect(db_path) as db:
        assert db.execute("PRAGMA integrity_check").fetchall() == [("ok",)]
