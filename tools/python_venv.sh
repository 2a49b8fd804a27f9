#!/usr/bin/env bash
# The Python environment for tests and tools that need PyPI packages Debian lacks (motmetrics):
# a venv in the ignored workspace folder on top of Debian's python3 and its packages
# (--system-site-packages: rospy, numpy, pandas, scipy come from Debian). Idempotent.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
venv="$WS/py-venv"
system_venv "$venv"
if ! "$venv/bin/python" -c "import motmetrics" 2> /dev/null; then
  # Its dependencies (pandas, scipy, xmltodict) are Debian packages (tools/apt-packages.txt).
  if ! "$venv/bin/pip" install -q --no-deps "motmetrics==1.4.0"; then
    # No PyPI (offline machine): everything else still works; the tracker-scoring pytest is
    # reported as skipped, not passed.
    echo "python: WARNING: could not install motmetrics from PyPI; its test will be skipped" >&2
    exit 0
  fi
fi
# pytest-xdist: the sanitized pytests run in two processes (make test-sanitize); without it they
# run in one, only slower.
if ! "$venv/bin/python" -c "import xdist" 2> /dev/null; then
  "$venv/bin/pip" install -q "pytest-xdist==3.8.0" ||
    echo "python: WARNING: no pytest-xdist from PyPI; make test-sanitize runs its pytests serially" >&2
fi
echo "python: $venv ($("$venv/bin/python" -c 'import motmetrics; print("motmetrics", motmetrics.__version__)'))"

# Build-time only: pybind11 >= 2.12 from PyPI, so that the compiled core exchanges arrays with
# numpy 1 and numpy 2 alike (Debian 12's pybind11 2.10 cannot read numpy 2's descriptors).
# tools/build.sh hands its CMake directory to catkin (pybind11_cmake_args in env.sh); offline,
# the build falls back to Debian's pybind11 and the package refuses numpy 2 at import.
build_venv="$WS/build-venv"
if ! "$build_venv/bin/python" -c "import pybind11" 2> /dev/null; then
  /usr/bin/python3 -m venv "$build_venv"
  "$build_venv/bin/pip" install -q "pybind11==2.13.6" ||
    echo "python: WARNING: no pybind11 from PyPI; the core is built with Debian's (numpy 1 only)" >&2
fi
# The core's pytests also run under numpy 2 (make test's pytest_numpy2): a venv without Debian's
# packages, so numpy is PyPI's 2.x; ROS-only tests skip there (no rospy, rosbag, ...).
np2_venv="$WS/np2-venv"
if ! "$np2_venv/bin/python" -c "import numpy, scipy, yaml, pytest" 2> /dev/null; then
  /usr/bin/python3 -m venv "$np2_venv"
  "$np2_venv/bin/pip" install -q "numpy==2.4.6" "scipy==1.17.1" "PyYAML==6.0.4" "pytest==9.2.0" ||
    echo "python: WARNING: no numpy 2 venv (PyPI unreachable); pytest_numpy2 is skipped" >&2
fi
