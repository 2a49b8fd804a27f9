#!/usr/bin/env bash
# Regenerates the type stubs of the compiled core (src/downstream_perception/_core.pyi) with
# pybind11-stubgen from PyPI, from the pip package that `make pip-check` installed in
# $WS/pip-venv (built with pybind11 3, whose signatures are proper numpy typing; the catkin
# build's pybind11 2.13 writes Eigen shapes mypy cannot read). Run `make pip-check` first.
# test_pip_package checks that the stubs name every entry point of the module.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
venv="$WS/pip-venv"
[[ -x "$venv/bin/python" ]] || { echo "stubs: run make pip-check first ($venv)" >&2; exit 1; }
"$venv/bin/python" -c "import pybind11_stubgen" 2> /dev/null ||
  "$venv/bin/pip" install -q "pybind11-stubgen==3.0.0"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
(cd "$out" && env -i PATH=/usr/bin:/bin HOME="$HOME" "$venv/bin/pybind11-stubgen" \
  --exit-code downstream_perception._core -o "$out")
cp "$out/downstream_perception/_core.pyi" "$REPO/src/downstream_perception/_core.pyi"
"$WS/tools-venv/bin/ruff" format -q --no-force-exclude "$REPO/src/downstream_perception/_core.pyi"
echo "stubs: $REPO/src/downstream_perception/_core.pyi"
