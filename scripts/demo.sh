#!/usr/bin/env bash
# Install what the GUI needs (not the test tools), then start the simulator and the GUI on
# http://127.0.0.1:5000 (Ctrl-C stops both).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh --gui
exec .venv/bin/python -m rover_web.demo "$@"
