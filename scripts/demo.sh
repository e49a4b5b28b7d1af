#!/usr/bin/env bash
# Install what the GUI needs (not the test tools), then start the simulator and the GUI on
# http://127.0.0.1:5000 (Ctrl-C stops both).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh --gui
.venv/bin/python -m rover_web.web.assets  # hashed, compressed static files (once per content; docs/page_load.md)
exec .venv/bin/python -m rover_web.demo "$@"
