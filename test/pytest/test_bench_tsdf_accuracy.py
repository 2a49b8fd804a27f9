"""The accuracy benchmark's scoring and bookkeeping (bench/bench_tsdf_accuracy.py), on ours only:
Open3D is not installed for the tests."""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest


@pytest.fixture(scope="module")
def bench(bench_script: Callable[[str], Any]) -> Any:
    return bench_script("bench_tsdf_accuracy")


@pytest.fixture(scope="module")
def room(bench: Any) -> tuple:
    """The room at a quarter of 320x240 (same field of view), 10 frames, a quarter-voxel offset
    at 5 cm, and its observed surface."""
    from downstream_perception.sim.depth_camera import DepthCamera
    from downstream_perception.sim.scenes import accuracy_scene
    from downstream_perception.tsdf_eval import observed_samples

    cam = bench.scaled(DepthCamera(), 0.5)
    assert (cam.width, cam.height, cam.fx) == (160, 120, 131.25)
    scene, poses = accuracy_scene("room", (0.0125,) * 3, frames=10)
    depths = [cam.render(scene, T) for T in poses]
    return cam, scene, poses, depths, observed_samples(scene, cam, poses, depths)


def test_ours_is_scored_and_pose_errors_show(bench: Any, room: tuple) -> None:
    cam, scene, poses, depths, observed = room
    clean = bench.score_case(bench.ours(), scene, cam, depths, poses, 0.05, observed)
    assert clean["vertices"] > 1000
    assert clean["mean_mm"] < 4.0
    assert clean["ghost_pct"] < 2.0
    assert clean["completeness"] > 0.9
    # Integrated at poses 10 cm off along x (two voxels): the mesh is off the true surfaces.
    off = [T.copy() for T in poses]
    for T in off:
        T[0, 3] += 0.1
    shifted = bench.score_case(bench.ours(), scene, cam, depths, off, 0.05, observed)
    assert shifted["mean_mm"] > 3 * clean["mean_mm"]
    assert shifted["ghost_pct"] > 10 * clean["ghost_pct"]
    # The noise cases are seeded: the same frames for every integrator.
    noise = bench.NOISES[3]
    d1, p1 = bench.noisy_frames(depths, poses, noise, seed=7)
    d2, p2 = bench.noisy_frames(depths, poses, noise, seed=7)
    np.testing.assert_array_equal(d1[0], d2[0])
    np.testing.assert_array_equal(p1[0], p2[0])
    assert 0.002 < np.nanstd(d1[0] - depths[0]) < 0.008
    assert np.abs(p1[0][:3, 3] - poses[0][:3, 3]).max() > 1e-4


def test_weld_merges_repeated_vertices(bench: Any) -> None:
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], float)
    triangles = np.array([[0, 1, 2], [3, 5, 4]])
    welded, remapped = bench.weld(vertices, triangles)
    assert len(welded) == 4
    np.testing.assert_array_equal(welded[remapped], vertices[triangles])


def test_summary_gives_median_and_range_over_scenes_and_offsets(bench: Any) -> None:
    def score(scene: str, offset: float, mean_mm: float, integrator: str = "ours") -> Any:
        return bench.Score("320x240", 0.05, "clean", integrator, scene, offset, 10, mean_mm,
                           2 * mean_mm, 0.1 * mean_mm, 1.0 - 0.01 * mean_mm)  # fmt: skip

    scores = [score("a", 0.0, 1.0), score("a", 0.5, 4.0), score("b", 0.0, 2.0)]
    scores.append(score("a", 0.0, 9.0, "other"))
    summary = bench.summarise(scores)
    ours = summary[("320x240", 0.05, "clean", "ours")]
    assert ours["cases"] == 3
    assert ours["mean_mm"] == (1.0, 2.0, 4.0)
    assert ours["completeness"] == pytest.approx((0.96, 0.98, 0.99))
    assert summary[("320x240", 0.05, "clean", "other")]["mean_mm"] == (9.0, 9.0, 9.0)
    table = "\n".join(bench.markdown(summary, "t"))
    assert "| 320x240, 5 cm | clean | ours | 3 | 2.00 (1.00–4.00) | 4.0 (2.0–8.0) |" in table


def test_cases_are_counted_against_legacy_on_the_same_frames(bench: Any) -> None:
    def score(integrator: str, scene: str, ghost_pct: float, completeness: float) -> Any:
        return bench.Score("320x240", 0.02, "clean", integrator, scene, 0.0, 10, 1.0, 2.0,
                           ghost_pct, completeness)  # fmt: skip

    scores = [
        score("Open3D legacy", "a", 0.4, 0.999),
        score("Open3D legacy", "b", 0.4, 0.990),
        score("ours", "a", 0.01, 0.998),  # less complete
        score("ours", "b", 0.01, 0.990),  # as complete, few ghosts: meets the goal
        score("ours", "c", 0.00, 1.000),  # no legacy case: not counted
        score("Open3D tensor", "a", 0.06, 0.999),  # as complete, too many ghosts
    ]
    counts = bench.against(scores)
    assert counts[("320x240", 0.02, "clean", "ours")] == {
        "cases": 2, "complete": 1, "ghosts": 2, "both": 1,
    }  # fmt: skip
    assert counts[("320x240", 0.02, "clean", "Open3D tensor")] == {
        "cases": 1, "complete": 1, "ghosts": 0, "both": 0,
    }  # fmt: skip
    assert ("320x240", 0.02, "clean", "Open3D legacy") not in counts
    table = "\n".join(bench.against_markdown(counts))
    assert "| 320x240, 2 cm | clean | ours | 2 | 1 | 2 | 1 |" in table
    assert bench.against_markdown(bench.against(scores[2:3])) == []


def test_near_mesh_matches_sampling_every_triangle(bench: Any, room: tuple) -> None:
    # score_mesh's completeness checks vertices first and samples only the triangles that could
    # matter: the same answer as sampling the whole mesh.
    from scipy.spatial import cKDTree

    from downstream_perception.tsdf_eval import near_mesh, sample_triangles

    cam, scene, poses, depths, observed = room
    noisy_depths, noisy_poses = bench.noisy_frames(depths, poses, bench.NOISES[3], seed=3)
    vertices, triangles = bench.weld(*bench.ours()(noisy_depths, noisy_poses, cam, 0.05))
    near = near_mesh(observed, vertices, triangles, 0.02)
    surface = sample_triangles(vertices, triangles, 0.005)
    distance, _ = cKDTree(surface).query(observed, distance_upper_bound=0.02)
    np.testing.assert_array_equal(near, np.isfinite(distance))
    assert 0.3 < near.mean() < 0.99  # both kinds of answer occur


def test_open3d_legacy_runs_on_our_lattice(bench: Any, monkeypatch: pytest.MonkeyPatch) -> None:
    # Open3D legacy puts its voxel centres at (i + 1/2) v, ours at i v: the bench integrates it in
    # a world moved by v/2 and moves its mesh back. Open3D is not installed here, so a stand-in
    # module records what legacy would be given.
    import types

    extrinsics: list[np.ndarray] = []

    class Volume:
        def __init__(self, **kwargs: Any) -> None:
            self.voxel = kwargs["voxel_length"]

        def integrate(self, frame: Any, intrinsic: Any, extrinsic: np.ndarray) -> None:
            extrinsics.append(np.asarray(extrinsic))

        def extract_triangle_mesh(self) -> Any:
            # A vertex on legacy's voxel centre (0 + 1/2) v in its moved world.
            v = 0.5 * self.voxel
            return types.SimpleNamespace(vertices=[[v, v, v]], triangles=[[0, 0, 0]])

    o3d = types.SimpleNamespace(
        camera=types.SimpleNamespace(PinholeCameraIntrinsic=lambda *a: a),
        geometry=types.SimpleNamespace(
            Image=lambda a: a,
            RGBDImage=types.SimpleNamespace(create_from_color_and_depth=lambda *a, **k: a),
        ),
        pipelines=types.SimpleNamespace(
            integration=types.SimpleNamespace(
                ScalableTSDFVolume=Volume,
                TSDFVolumeColorType=types.SimpleNamespace(NoColor=0),
            )
        ),
    )
    monkeypatch.setitem(sys.modules, "open3d", o3d)
    cam = types.SimpleNamespace(width=4, height=3, fx=2.0, fy=2.0, cx=1.5, cy=1.0)
    pose = np.eye(4)
    pose[:3, 3] = (1.0, 2.0, 3.0)
    depth = np.ones((3, 4), np.float32)
    vertices, _ = bench.open3d_legacy([depth], [pose], cam, 0.02)
    np.testing.assert_allclose(vertices, [[0.0, 0.0, 0.0]], atol=1e-12)  # on our centre 0
    # The camera seen from the moved world: a point at x in ours is at x + v/2 in legacy's.
    point = np.array([0.3, -0.2, 0.7, 1.0])
    moved = point + np.array([0.01, 0.01, 0.01, 0.0])
    np.testing.assert_allclose(extrinsics[0] @ moved, np.linalg.inv(pose) @ point, atol=1e-12)
    native, _ = bench.open3d_legacy([depth], [pose], cam, 0.02, native_lattice=True)
    np.testing.assert_allclose(native, [[0.01, 0.01, 0.01]], atol=1e-12)
    np.testing.assert_allclose(extrinsics[1], np.linalg.inv(pose), atol=1e-12)


def test_variants_of_ours_set_their_tsdf_config_values(
    bench: Any, room: tuple, monkeypatch: pytest.MonkeyPatch
) -> None:
    import downstream_perception as dp

    settings = bench.parse_settings("unconfirmed_update_weight=0.05,carve_free_space=true")
    assert settings == (("unconfirmed_update_weight", 0.05), ("carve_free_space", True))
    assert settings[1][1] is True  # typed as the key is, not 1.0
    assert bench.parse_settings("incidence_window_radius_px=3")[0][1].__class__ is int
    assert bench.parse_settings("default") == ()
    bad_ones = ("no_such_key=1", "unconfirmed_update_weight", "carve_free_space=1", "_x=1")
    for bad in (*bad_ones, "incidence_window_radius_px=2.5"):
        with pytest.raises(ValueError):
            bench.parse_settings(bad)
    with pytest.raises(ValueError):
        bench.parse_settings("unconfirmed_update_weight=heavy")
    names = list(
        bench.integrators([bench.DEFAULT_EDGE_GUARD_RAD], variants=[(), settings], open3d=False)
    )
    assert names == ["ours", "ours, unconfirmed_update_weight 0.05, carve_free_space on"]
    # --dropoff and --mesh-extrapolate are settings too, crossed with every variant.
    off, zero = (("behind_surface_dropoff", False),), (("mesh_extrapolate_voxels", 0.0),)
    crossed = bench.crossed_variants([(), settings], [(), off], [zero])
    assert [bench.settings_name(v) for v in crossed] == [
        ", mesh_extrapolate_voxels 0",
        ", mesh_extrapolate_voxels 0, unconfirmed_update_weight 0.05, carve_free_space on",
        ", behind_surface_dropoff off, mesh_extrapolate_voxels 0",
        ", behind_surface_dropoff off, mesh_extrapolate_voxels 0, unconfirmed_update_weight 0.05"
        ", carve_free_space on",
    ]
    # The values reach the map's config (after the bench's own: truncation_voxels too).
    seen = []
    real = dp.Tsdf

    def recording(config: Any) -> Any:
        seen.append(config)
        return real(config)

    monkeypatch.setattr(dp, "Tsdf", recording)
    cam, scene, poses, depths, observed = room
    override = settings + (("truncation_voxels", 3.0),)
    row = bench.score_case(bench.ours(settings=override), scene, cam, depths, poses, 0.05, observed)
    assert row["vertices"] > 1000
    assert seen[-1].unconfirmed_update_weight == pytest.approx(0.05)
    assert seen[-1].carve_free_space is True
    assert seen[-1].truncation_voxels == 3.0
    bench.ours()(depths[:1], poses[:1], cam, 0.05)
    assert seen[-1].unconfirmed_update_weight == 1.0
    assert seen[-1].truncation_voxels == bench.TRUNCATION_VOXELS
