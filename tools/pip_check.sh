#!/usr/bin/env bash
# `pip install .` as a Python user without ROS does it (docs/python.md, "Python without ROS"): a fresh venv
# with no system site packages ($WS/pip-venv, numpy 2 from PyPI), the package built by pip
# (pyproject.toml, scikit-build-core, pybind11 from PyPI) from a copy of the tracked files, then
# the pytests in that venv with an environment that has no ROS in it (env -i): the ones that need
# rospy, rosbag, rosrun or the catkin workspace skip, every other one must pass.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
venv="$WS/pip-venv"
src="$WS/pip-src"
rm -rf "$venv" "$src"
mkdir -p "$src"
# The tracked files only (a clean checkout's view), so nothing built in place leaks in.
git -C "$REPO" ls-files -z | (cd "$REPO" && xargs -0 cp --parents -t "$src")
/usr/bin/python3 -m venv "$venv"
log="$WS/pip_install.log"
if ! CMAKE_BUILD_PARALLEL_LEVEL=2 "$venv/bin/pip" install "$src[test]" > "$log" 2>&1; then
  if grep -q -E "Could not find a version|No matching distribution|Network is unreachable" "$log"; then
    echo "pip-check: SKIPPED: PyPI unreachable (scikit-build-core, pybind11); see $log" >&2
    exit 0
  fi
  tail -30 "$log"
  echo "pip-check: pip install . failed (log: $log)" >&2
  exit 1
fi
echo "pip-check: installed $("$venv/bin/python" -c 'import importlib.metadata as m; print("downstream-perception", m.version("downstream-perception"))') with numpy $("$venv/bin/python" -c 'import numpy; print(numpy.__version__)')"
# From the copy's test folder, so that the repository's src/ is not on the path: the tests must
# import the installed package.
cd "$src"
env -i PATH=/usr/bin:/bin HOME="$HOME" DP_PIP_PACKAGE=1 \
  "$venv/bin/python" -m pytest -q -p no:cacheprovider test/pytest "$@"
