#!/usr/bin/env bash
# Install everything, then lint and run the whole test suite (unit, ROS integration, Chromium browser tests).
# Extra arguments go to pytest, e.g. scripts/test.sh tests/unit -x
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/bootstrap.sh --browser
# Lint first: it takes a second, and a red lint should not wait behind a 15-minute suite.
echo "== ruff check"
.venv/bin/ruff check rover_web tests bench scripts
# Two workers (pytest-xdist), one per core of CI's: the suite is mostly waiting on servers, ROS peers
# and Chromium, but three made its timing tests flaky (docs/testing.md). ROVER_WEB_TEST_WORKERS=0
# runs it in one process.
.venv/bin/python -m rover_web.web.assets  # the static store once, not by each worker's first app
exec .venv/bin/python -m pytest -n "${ROVER_WEB_TEST_WORKERS:-2}" "$@"
