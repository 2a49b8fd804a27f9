#!/usr/bin/env bash
# Creates the catkin workspace in .ws (the repository is linked in as its only source package)
# and builds it (Release, tests included). Incremental on a second run.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
mkdir -p "$WS/src" "$ROS_HOME"
link_package "$WS"
cd "$WS"
if [[ -f build/CMakeCache.txt ]] && ! grep -q "PYTHON_EXECUTABLE:FILEPATH=/usr/bin/python3" build/CMakeCache.txt; then
  rm -rf build devel  # a cache configured with another python (pitfall P14)
fi
# shellcheck disable=SC2046 # one argument or none
if ! catkin_make -j2 -DCMAKE_BUILD_TYPE=Release -DCATKIN_ENABLE_TESTING=ON \
    -DPYTHON_EXECUTABLE=/usr/bin/python3 $(pybind11_cmake_args) "$@" > "$WS/build.log" 2>&1; then
  grep -E 'error|Error' "$WS/build.log" | head -40 || true
  tail -40 "$WS/build.log"
  echo "build: catkin_make failed (full log: $WS/build.log)" >&2
  exit 1
fi
warnings="$(grep 'warning:' "$WS/build.log" | grep -vc 'lto-wrapper' || true)"
echo "build: ok ($warnings compiler warning(s); log: $WS/build.log)"
