"""The side-by-side benchmark's bookkeeping (bench/bench_open3d.py), with stand-in integrators:
Open3D itself is not installed for the tests."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


@pytest.fixture(scope="module")
def bench(bench_script: Callable[[str], Any]) -> Any:
    return bench_script("bench_open3d")


def test_rounds_alternate_and_ratios_are_per_round(bench: Any) -> None:
    calls: list[str] = []
    # A shared machine's phases: round 2 runs everything twice as slowly.
    phase = iter([1.0, 1.0, 2.0, 2.0])

    def fake(name: str, ms: float, mesh_ms: float) -> Any:
        def integrate(depths: Any, poses: Any, cam: Any) -> Any:
            calls.append(name)
            scale = next(phase)
            # The median per frame ignores the one outlier.
            return bench.Timing([ms * scale, ms * scale, 100.0 * ms], mesh_ms * scale)

        return integrate

    timings = bench.interleave(
        {"ours": fake("ours", 3.0, 20.0), "other": fake("other", 9.0, 100.0)}, [], [], None, 2
    )
    assert calls == ["ours", "other", "ours", "other"]
    assert [t.mesh_ms for t in timings["other"]] == [100.0, 200.0]
    summary = bench.summarise(timings, "ours")
    assert summary["other"]["ratio"] == pytest.approx(3.0)  # the slow phase cancels
    assert summary["other"]["mesh_ratio"] == pytest.approx(5.0)
    assert summary["ours"]["ratio"] == pytest.approx(1.0)
    assert summary["other"]["median_ms"] == pytest.approx(13.5)
    assert summary["other"]["mesh_ms"] == pytest.approx(150.0)
    assert (summary["other"]["min_ms"], summary["other"]["max_ms"]) == (9.0, 18.0)
    table = "\n".join(bench.markdown({"320x240": summary}, 2))
    assert "| 320x240 | other | 13.50 (9.00–18.00) | 3.00 | 150.0 | 5.00 |" in table


def test_ours_times_each_frame_and_rejects_missing_poses(bench: Any) -> None:
    from downstream_perception.sim.depth_camera import DepthCamera, circle_poses, room_scene

    cam = DepthCamera()
    poses = [np.asarray(T, dtype=np.float64) for T in circle_poses(3)]
    depths = [np.ascontiguousarray(cam.render(room_scene(), T), dtype=np.float32) for T in poses]
    timing = bench.ours(depths, poses, cam)
    assert len(timing.frame_ms) == 3  # one entry per frame (how long each took is for benches)
    with pytest.raises(ValueError):  # strict zip: a pose missing is an error, not a short run
        bench.ours(depths, poses[:2], cam)
