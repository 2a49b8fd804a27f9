"""`rosrun downstream_perception <x>` resolves every script and node of the package to one file.

rosrun searches the package directory recursively; when the workspace was a link to the
repository inside the repository, every script was found several times (devel, build, the link
loop) and rosrun refused to pick one.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGE = "downstream_perception"


def _scripts() -> list[str]:
    # The nodes and the demo (scripts/) and the benchmark tools run by name (bench/).
    folders = (REPO / "scripts", REPO / "bench")
    return sorted(p.name for d in folders for p in d.iterdir() if os.access(p, os.X_OK))


def _nodes() -> list[str]:
    text = (REPO / "CMakeLists.txt").read_text()
    return sorted(re.findall(r"add_executable\((\w+_node) ", text))


def _resolve(name: str) -> subprocess.CompletedProcess[str]:
    # --prefix echo: rosrun prints the command it would run instead of running it.
    return subprocess.run(
        ["rosrun", "--prefix", "echo", PACKAGE, name],
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )


def test_the_lists_are_not_empty() -> None:
    assert "sim_node.py" in _scripts()
    assert "costmap_compare.py" in _scripts()
    assert "costmap_node" in _nodes()


@pytest.mark.skipif(shutil.which("rosrun") is None, reason="rosrun is not installed")
@pytest.mark.skipif(
    os.environ.get("DP_PIP_PACKAGE") == "1", reason="pip package: no catkin workspace, no ROS"
)
@pytest.mark.parametrize("name", _scripts() + _nodes())
def test_rosrun_finds_exactly_one(name: str) -> None:
    if name in _nodes() and os.environ.get("DP_PARTIAL_BUILD") == "1":
        pytest.skip("this build (the sanitizer workspace) does not build the nodes")
    result = _resolve(name)
    assert result.returncode == 0, f"rosrun {PACKAGE} {name}: {result.stdout}{result.stderr}"
    lines = [line for line in result.stdout.splitlines() if line.strip()]
    assert len(lines) == 1, f"rosrun {PACKAGE} {name} printed {lines}"
    path = Path(lines[0].split()[0])
    assert path.is_file() and path.name == name, lines[0]
