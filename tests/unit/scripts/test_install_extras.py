"""scripts/demo.sh installs what the GUI runs with, not the test tools (issue 40); scripts/bootstrap.sh
without --gui (scripts/test.sh, a deployment) still installs them. Run for real, with a stand-in
.venv/bin/python that writes down what it was asked to install instead of installing it."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
FAKE_PYTHON = """#!/usr/bin/env bash
echo "$*" >> "$(dirname "$0")/calls"
[[ "$1" == "-c" ]] && exit 1   # `import rclpy` fails: ROS is not sourced, so the ros extra is installed
exit 0
"""


def installs(tmp_path: Path, script: str, *args: str) -> list[str]:
    for name in ("demo.sh", "bootstrap.sh"):
        (tmp_path / "scripts").mkdir(exist_ok=True)
        shutil.copy(ROOT / "scripts" / name, tmp_path / "scripts" / name)
    shutil.copy(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    # The interface build (scripts/build_interfaces.sh) is not what this test is about: it has a
    # test of its own (tests/unit/test_interfaces.py); here it only has to be called.
    (tmp_path / "scripts" / "build_interfaces.sh").write_text('#!/usr/bin/env bash\necho "$0 $*" >> built\n')
    (tmp_path / "scripts" / "build_interfaces.sh").chmod(0o755)
    # esbuild (the page bundles) is here already, at the pinned version: no npm install in a test.
    version = next(line for line in (ROOT / "rover_web" / "web" / "bundles.py").read_text().splitlines()
                   if line.startswith("ESBUILD_VERSION = "))
    (tmp_path / "rover_web" / "web").mkdir(parents=True, exist_ok=True)
    (tmp_path / "rover_web" / "web" / "bundles.py").write_text(version + "\n")
    esbuild = tmp_path / ".tools" / "esbuild" / "node_modules" / "@esbuild" / "linux-x64" / "bin" / "esbuild"
    esbuild.parent.mkdir(parents=True, exist_ok=True)
    esbuild.write_text(f'#!/usr/bin/env bash\necho {version.split(chr(34))[1]}\n')
    esbuild.chmod(0o755)
    venv = tmp_path / ".venv" / "bin"
    venv.mkdir(parents=True, exist_ok=True)
    (venv / "python").write_text(FAKE_PYTHON)
    (venv / "python").chmod(0o755)
    (venv / "calls").unlink(missing_ok=True)
    env = {k: v for k, v in os.environ.items() if k != "AMENT_PREFIX_PATH"}
    done = subprocess.run([str(tmp_path / "scripts" / script), *args], env=env, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 0, done.stderr
    calls = venv / "calls"
    made = calls.read_text().splitlines() if calls.exists() else []
    return [call for call in made if "pip install" in call and " -e " in call]


def test_the_demo_installs_the_gui_without_the_test_tools(tmp_path):
    assert installs(tmp_path, "demo.sh") == ["-m pip install --quiet -e .[ros]"]


def test_the_default_bootstrap_still_installs_the_test_tools_and_a_changed_choice_installs_again(tmp_path):
    installs(tmp_path, "demo.sh")
    assert installs(tmp_path, "bootstrap.sh") == ["-m pip install --quiet -e .[ros,test,serve]"]
    assert installs(tmp_path, "bootstrap.sh") == []  # nothing changed: nothing installed
