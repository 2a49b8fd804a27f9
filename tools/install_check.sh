#!/usr/bin/env bash
# make install-check: builds the install space (.ws/install) and runs tools/install_smoke.py from
# it alone, in an environment that has neither the repository nor the devel space on any path:
# the Python package and its compiled core, the messages and services, plugin discovery and a
# launch of the costmap nodelet that must publish its grid.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
cd "$WS"
if ! catkin_make -j2 install > "$WS/install.log" 2>&1; then
  tail -40 "$WS/install.log"
  echo "install-check: catkin_make install failed (log: $WS/install.log)" >&2
  exit 1
fi
# A copy of the smoke script outside the repository, so nothing of the source tree is importable.
smoke="$(mktemp -d)"
trap 'rm -rf "$smoke"' EXIT
cp "$REPO/tools/install_smoke.py" "$smoke/"
cd "$smoke"
env -i HOME="$HOME" PATH=/usr/bin:/bin ROS_HOSTNAME=localhost ROS_HOME="$WS/ros_home" \
  bash -c "source '$WS/install/setup.bash' && python3 install_smoke.py '$WS/install' '$REPO'"
