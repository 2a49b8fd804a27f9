"""The ROS-free core as a build rule (tools/check_core_boundary.py): its sources include no ROS
header, and the built library needs no ROS library and read no ROS header. Each check is also
shown to catch a violation, so that it cannot pass by looking at nothing."""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "tools"))

import check_core_boundary as boundary  # noqa: E402


def _devel_lib() -> Path:
    import downstream_perception._core as core

    # <devel>/lib/python3/dist-packages/downstream_perception/_core.*.so
    return Path(core.__file__).resolve().parents[3]


def _build_dir() -> Path:
    return _devel_lib().parent.parent / "build" / "downstream_perception"


def test_core_sources_include_nothing_of_ros() -> None:
    assert boundary.check_sources() == []
    assert sum(1 for _ in boundary.core_files()) > 40  # it looked at the core


def test_a_ros_include_in_the_core_is_caught(tmp_path: Path) -> None:
    core = tmp_path / "src" / "core" / "grid"
    core.mkdir(parents=True)
    (core / "bad.cpp").write_text(
        "#include <vector>\n#include <Eigen/Core>\n"
        '#include "downstream_perception/core/grid/se2.h"\n'
        "#include <ros/ros.h>\n"
        '#include "downstream_perception/ros/common/param_reader.h"\n'
    )
    (tmp_path / "include" / "downstream_perception" / "core").mkdir(parents=True)
    problems = boundary.check_sources(tmp_path)
    assert len(problems) == 2
    assert "bad.cpp:4" in problems[0] and "'ros/'" in problems[0]
    assert "bad.cpp:5" in problems[1] and "ROS glue" in problems[1]


@pytest.mark.skipif(shutil.which("readelf") is None, reason="readelf (binutils) is not installed")
@pytest.mark.skipif(
    os.environ.get("DP_PIP_PACKAGE") == "1", reason="pip package: no catkin build of the core"
)
def test_the_built_core_needs_no_ros() -> None:
    library = _devel_lib() / "libdownstream_perception_core.so"
    assert library.is_file(), library
    assert boundary.check_built(_build_dir(), library) == []


@pytest.mark.skipif(shutil.which("readelf") is None, reason="readelf (binutils) is not installed")
def test_a_ros_library_is_caught() -> None:
    # The costmap host is ROS glue: it links roscpp's and tf2's libraries.
    glue = _devel_lib() / "libdownstream_perception_costmap.so"
    if not glue.is_file():
        pytest.skip("this build (the sanitizer workspace) does not build the ROS glue")
    problems = boundary.check_built(_build_dir(), glue)
    assert any("needs the ROS library" in p for p in problems), problems
