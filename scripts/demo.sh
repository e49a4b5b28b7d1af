#!/usr/bin/env bash
# Install everything, then start the simulator and the GUI on http://127.0.0.1:5000 (Ctrl-C stops both).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh
exec .venv/bin/python -m rover_web.demo "$@"
