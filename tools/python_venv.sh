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
echo "python: $venv ($("$venv/bin/python" -c 'import motmetrics; print("motmetrics", motmetrics.__version__)'))"
