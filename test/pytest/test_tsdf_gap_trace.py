"""The gap trace (bench/tsdf_gap_trace.py): part labels, the per-part bookkeeping, and that a
case's frames are the accuracy benchmark's (ours only: Open3D is not installed for the tests)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


@pytest.fixture(scope="module")
def gap(bench_script: Callable[[str], Any]) -> Any:
    return bench_script("tsdf_gap_trace")


def test_samples_are_labelled_with_the_nearest_part_and_box_edges(gap: Any) -> None:
    from downstream_perception.sim.depth_camera import Box, Cylinder, Scene3D, Sphere

    scene = Scene3D(
        room_min=(-2.0, -2.0, 0.0),
        room_max=(2.0, 2.0, 3.0),
        boxes=[Box((0.0, 0.0, 0.5), (0.3, 0.2, 0.1))],
        spheres=[Sphere((1.0, 1.0, 1.0), 0.2)],
        cylinders=[Cylinder((-1.0, 1.0), 0.05, 0.0, 3.0)],
    )
    points = np.array(
        [
            [0.0, 0.0, 0.6],  # the box's top, in its middle
            [0.0, 0.19, 0.6],  # the top, 1 cm from its y+ face: an edge at 2 cm voxels
            [0.3, 0.0, 0.44],  # the box's x+ face, 4 cm from its bottom face
            [-0.3, 0.0, 0.5],  # the x- face, 10 cm from the top and bottom: a face
            [0.5, -1.0, 0.0],  # the floor
            [2.0, 0.5, 1.5],  # the x+ wall
            [1.0, 1.0, 1.2],  # the sphere's top
            [-0.95, 1.0, 2.0],  # the cylinder's side
        ]
    )
    labels = gap.part_labels(scene, points, 0.02)
    assert list(labels) == [
        "box 0 z+",
        "box 0 z+ edge",
        "box 0 x+",
        "box 0 x-",
        "wall z-",
        "wall x+",
        "sphere 0",
        "cylinder 0",
    ]
    # The edge margin is the voxel: at 5 cm the x+ face's point is an edge too.
    assert gap.part_labels(scene, points[2:3], 0.05)[0] == "box 0 x+ edge"


def test_lost_and_gained_are_counted_per_part_most_lost_first(gap: Any) -> None:
    labels = np.array(["a", "a", "a", "b", "b", "c"], dtype=object)
    near_a = np.array([True, False, False, True, True, True])
    near_b = np.array([True, True, True, False, True, True])
    rows = gap.gaps(labels, near_a, near_b)
    assert [r.part for r in rows] == ["a", "c", "b"]
    a, c, b = rows
    assert (a.samples, a.lost, a.gained) == (3, 2, 0)
    assert a.covered_a == pytest.approx(1 / 3) and a.covered_b == pytest.approx(1.0)
    assert (b.samples, b.lost, b.gained, b.covered_a, b.covered_b) == (2, 0, 1, 1.0, 0.5)
    assert (c.lost, c.gained) == (0, 0)
    lines = gap.markdown({"a": 0.5, "b": 0.75}, rows, top=2)
    assert lines[0] == "completeness: A 0.5000, B 0.7500"
    assert lines[-1] == "| c | 1 | 1.000 | 1.000 | 0 | 0 |" and len(lines) == 6


def test_a_case_is_the_benchmarks_and_the_same_settings_differ_nowhere(gap: Any) -> None:
    bench = gap.load_bench()
    # With depth noise (index 1), so the case's noise seed must be the benchmark's too.
    completeness, rows = gap.trace(
        bench, "room", 0.5, 0.05, noise_index=1, ours="default", against="default", frames=6
    )
    assert completeness["a"] == completeness["b"]
    assert sum(r.samples for r in rows) > 10_000
    assert all(r.lost == 0 and r.gained == 0 for r in rows)
    assert {"wall z-", "sphere 0"} <= {r.part for r in rows}
    # The benchmark scores the very same frames: the same completeness for the same settings.
    scores = bench.run(
        ["room"], [0.5], [bench.NOISES[1]], [("320x240", 0.05)],
        [bench.DEFAULT_EDGE_GUARD_RAD], frames=6, log=lambda _: None, open3d=False,
    )  # fmt: skip
    assert len(scores) == 1
    assert scores[0].completeness == pytest.approx(completeness["a"], abs=1e-12)
    # Another setting does differ somewhere: no guard at all writes behind every rim.
    _, other = gap.trace(bench, "room", 0.5, 0.05, against="edge_guard_rad=0", frames=6)
    assert sum(r.lost + r.gained for r in other) > 0


def test_bad_arguments_are_refused(gap: Any, capsys: pytest.CaptureFixture[str]) -> None:
    for argv in (
        ["--scene", "room", "--noise", "9", "--against", "default"],
        ["--scene", "room", "--voxel-cm", "0", "--against", "default"],
        ["--scene", "room", "--against", "no_such_key=1"],
    ):
        with pytest.raises(SystemExit) as exit_info:
            gap.main(argv)
        assert exit_info.value.code == 2
    assert "no_such_key" in capsys.readouterr().err
