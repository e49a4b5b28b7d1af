#!/usr/bin/env bash
# Build the ROS 2 interface packages rover_web uses that PyPI has no wheel for (tf2_msgs, nav2_msgs;
# their definitions are in interfaces/) and install them into .venv, beside the message wheels.
#
# A robot with /opt/ros/jazzy sourced has the real packages and needs none of this: the script
# then does nothing. Elsewhere (the demo, the tests, CI) it builds them once with ROS 2's own
# generators (the ros-jazzy-* rosidl wheels) in a build venv of their own, about a minute, and
# skips the work while interfaces/ is unchanged.
#
# Usage: scripts/build_interfaces.sh [VENV]   (default .venv)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
venv=$(realpath "${1:-.venv}")
py="$venv/bin/python"
site=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')

digest=$(cat scripts/build_interfaces.sh interfaces/*/package.xml interfaces/*/CMakeLists.txt \
         interfaces/*/*/*.msg interfaces/*/*/*.action | sha256sum | cut -d' ' -f1)
stamp="$venv/.rover_web-interfaces"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$digest" ]] && "$py" -c 'import tf2_msgs.msg, nav2_msgs.action' 2>/dev/null; then
  exit 0
fi
if [[ -z "${ROVER_WEB_BUILD_INTERFACES_ANYWAY:-}" && -n "${AMENT_PREFIX_PATH:-}" ]] \
   && "$py" -c 'import tf2_msgs.msg, nav2_msgs.action' 2>/dev/null; then
  exit 0   # a sourced ROS 2 install has the real ones
fi

echo "== building tf2_msgs and nav2_msgs from interfaces/ (no wheel on PyPI; about a minute, once)"
if ! command -v cmake >/dev/null || ! command -v g++ >/dev/null; then
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -q
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q cmake g++ make
fi

work="$root/build/interfaces"
bvenv="$work/venv"
rm -rf "$work/build" "$work/stage"
mkdir -p "$work"
if [[ ! -x "$bvenv/bin/python" ]]; then
  "$py" -m venv "$bvenv"
fi
# ROS 2's own generators, pinned to the Jazzy releases of the runtime wheels rover_web installs
# (pyproject.toml's `ros` extra), and numpy at the venv's own version (the Python typesupport is
# compiled against its headers). The wheels declare no build dependencies, hence the list.
numpy_version=$("$py" -c 'import numpy; print(numpy.__version__)')
gen=(rosidl-default-generators==1.6.0 rosidl-core-generators==0.2.0 rosidl-cmake==4.6.6
     rosidl-generator-c==4.6.6 rosidl-generator-cpp==4.6.6 rosidl-generator-py==0.22.2
     rosidl-generator-type-description==4.6.6 rosidl-typesupport-c==3.2.2 rosidl-typesupport-cpp==3.2.2
     rosidl-typesupport-fastrtps-c==3.6.2 rosidl-typesupport-fastrtps-cpp==3.6.2
     rosidl-typesupport-introspection-c==4.6.6 rosidl-typesupport-introspection-cpp==4.6.6
     ament-package==0.16.4 ament-cmake==2.5.4 ament-cmake-core==2.5.4 ament-cmake-export-definitions==2.5.4
     ament-cmake-export-dependencies==2.5.4 ament-cmake-export-include-directories==2.5.4
     ament-cmake-export-interfaces==2.5.4 ament-cmake-export-libraries==2.5.4 ament-cmake-export-link-flags==2.5.4
     ament-cmake-export-targets==2.5.4 ament-cmake-gen-version-h==2.5.4 ament-cmake-include-directories==2.5.4
     ament-cmake-libraries==2.5.4 ament-cmake-python==2.5.4 ament-cmake-ros==0.12.0
     ament-cmake-target-dependencies==2.5.4 ament-cmake-test==2.5.4 ament-cmake-version==2.5.4
     fastrtps-cmake-module==3.6.2 fastcdr==2.2.5 fastrtps==2.14.5 rosidl-runtime-c==4.6.6 rosidl-runtime-cpp==4.6.6
     rosidl-dynamic-typesupport==0.1.2 rcutils==6.7.4 rcpputils==2.11.2 rmw==7.3.2
     ament-cmake-gmock==2.5.4 ament-cmake-gtest==2.5.4 ament-cmake-pytest==2.5.4 gmock-vendor==1.14.9000
     gtest-vendor==1.14.9000 domain-coordinator==0.12.0 python-cmake-module==0.11.1 rpyutils==0.4.2
     service-msgs==2.0.3 type-description-interfaces==2.0.3 unique-identifier-msgs==2.5.0
     geometry-msgs==5.3.6 action-msgs==2.0.3 builtin-interfaces==2.0.3 std-msgs==5.3.6)
"$bvenv/bin/python" -m pip install --quiet --disable-pip-version-check "${gen[@]/#/ros-jazzy-}" \
  catkin_pkg==1.1.0 "numpy==$numpy_version"

# The message wheels' exported CMake files name the include folders of the machine that built the
# wheels; point them at this Python's headers and numpy's.
py_include=$("$bvenv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
np_include=$("$bvenv/bin/python" -c 'import numpy; print(numpy.get_include())')
{ grep -rl '/opt/python/cp311-cp311' "$bvenv/share" --include='*.cmake' || true; } | while read -r f; do
  sed -i -e "s#/opt/python/cp311-cp311/include/python3.11#$py_include#g" \
         -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$np_include#g" "$f"
done

export AMENT_PREFIX_PATH="$bvenv" CMAKE_PREFIX_PATH="$bvenv"
export PATH="$bvenv/bin:$PATH" LD_LIBRARY_PATH="$bvenv/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
for pkg in tf2_msgs nav2_msgs; do
  cmake -S "interfaces/$pkg" -B "$work/build/$pkg" -DCMAKE_BUILD_TYPE=Release -DBUILD_TESTING=OFF \
    -DCMAKE_INSTALL_PREFIX="$work/stage" -DPython3_EXECUTABLE="$bvenv/bin/python" \
    -DPYTHON_EXECUTABLE="$bvenv/bin/python" >"$work/$pkg.cmake.log" 2>&1 \
    || { tail -30 "$work/$pkg.cmake.log" >&2; exit 1; }
  cmake --build "$work/build/$pkg" -j "$(nproc)" >"$work/$pkg.build.log" 2>&1 \
    || { tail -30 "$work/$pkg.build.log" >&2; exit 1; }
  cmake --install "$work/build/$pkg" >/dev/null
done

# Into the venv, laid out as the message wheels are: libraries in <venv>/lib (the ROS wheels put
# it on LD_LIBRARY_PATH), Python packages in site-packages, share/ for the ament index.
cp -a "$work/stage/lib/"*.so "$venv/lib/"
for pkg in tf2_msgs nav2_msgs; do
  rm -rf "${site:?}/$pkg"
  cp -a "$work/stage/lib/python3.11/site-packages/$pkg" "$site/"
done
mkdir -p "$venv/share"
cp -a "$work/stage/share/." "$venv/share/"
"$py" -c 'import tf2_msgs.msg, nav2_msgs.action' || { echo "built, but not importable" >&2; exit 1; }
echo "$digest" > "$stamp"
echo "== tf2_msgs and nav2_msgs installed into $venv"
