"""`python -m rover_web.web.assets`, the command scripts/test.sh and scripts/demo.sh run before a start."""

import os
import subprocess
import sys

from rover_web.config import ROOT


def test_the_store_filling_command_hashes_and_compresses_static(tmp_path):
    done = subprocess.run([sys.executable, "-m", "rover_web.web.assets"], cwd=ROOT, capture_output=True, text=True,
                          timeout=120, env={**os.environ, "ROVER_WEB_STATIC_BUILD_DIR": str(tmp_path)})
    assert done.returncode == 0, done.stderr
    assert "hashed and compressed" in done.stdout
    made = {p.suffix for p in tmp_path.rglob("*") if p.is_file()}
    assert {".js", ".css", ".br", ".gz"} <= made, made
