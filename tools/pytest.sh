#!/usr/bin/env bash
# Runs pytest with the project's venv python when it exists (PyPI extras such as motmetrics),
# else with Debian's python3. Arguments go to pytest.
set -euo pipefail
here="$(cd -P "$(dirname "${BASH_SOURCE[0]}")" && pwd)"  # -P: the repository, not the workspace's link to it
python="$here/../.ws/py-venv/bin/python"
[[ -x "$python" ]] || python=/usr/bin/python3
exec "$python" -m pytest "$@"
