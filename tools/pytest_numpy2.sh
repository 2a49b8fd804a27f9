#!/usr/bin/env bash
# The pytests under numpy 2: the venv tools/python_venv.sh made from PyPI (numpy 2.x, no Debian
# packages, so the tests that need rospy, rosbag or dynamic_reconfigure skip). Without that venv
# (PyPI unreachable) only test_numpy_versions runs, and reports itself skipped. Arguments go to
# pytest.
set -euo pipefail
here="$(cd -P "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
python="$here/../.ws/np2-venv/bin/python"
if [[ -x "$python" ]] && "$python" -c "import numpy, pytest" 2> /dev/null; then
  DP_EXPECT_NUMPY2=1 exec "$python" -m pytest "$@"
fi
echo "pytest_numpy2: no numpy 2 venv (.ws/np2-venv); make deps makes it when PyPI is reachable" >&2
DP_NUMPY2_MISSING=1 exec /usr/bin/python3 -m pytest "$@" -k test_numpy_versions
