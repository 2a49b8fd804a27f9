#!/usr/bin/env bash
# ruff (Python) and clang-format (C++) checks. ruff comes from PyPI into a venv inside the ignored
# workspace folder, pinned so results do not change under us.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
venv="$WS/tools-venv"
if [[ ! -x "$venv/bin/ruff" ]]; then
  /usr/bin/python3 -m venv "$venv"
  "$venv/bin/pip" install -q "ruff==0.8.6"
fi
[[ -x "$venv/bin/catkin_lint" ]] || "$venv/bin/pip" install -q "catkin_lint==1.6.25"
cd "$REPO"
"$venv/bin/ruff" check src scripts bench test tools
"$venv/bin/ruff" format --check src scripts bench test tools
python3 tools/check_core_boundary.py sources
clang-format --dry-run --Werror $(git ls-files '*.cpp' '*.h')
# catkin_lint: errors fail (warnings and notices are listed). No rosdep database here, so it
# cannot resolve system keys (it says so and goes on).
"$venv/bin/catkin_lint" -q "$REPO"
echo "lint: ok"
