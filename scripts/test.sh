#!/usr/bin/env bash
# Install everything, then run the whole test suite (unit, ROS integration, Chromium browser tests).
# Extra arguments go to pytest, e.g. scripts/test.sh tests/unit -x
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh --browser
exec .venv/bin/python -m pytest "$@"
