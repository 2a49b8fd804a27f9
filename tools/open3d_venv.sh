#!/usr/bin/env bash
# Open3D 0.19 for the side-by-side TSDF benchmark only (make bench-open3d); not a dependency of
# the package, its tests or its demo. A venv in the ignored workspace folder on top of Debian's
# python3, so numpy and the built workspace's packages stay Debian's.
# 0.19.0, not 0.20.0: 0.20.0's legacy volume integrates nothing (issue 5). Idempotent.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
venv="$WS/open3d-venv"
system_venv "$venv"
if ! "$venv/bin/python" -c "import open3d" 2> /dev/null; then
  "$venv/bin/pip" install -q "open3d-cpu==0.19.0"
fi
echo "open3d: $venv ($("$venv/bin/python" -c 'import open3d; print(open3d.__version__)'))"
