"""pytest: the TSDF core through Python, on the lesson's numbers and the simulated room."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

dp = pytest.importorskip("downstream_perception._core", reason="compiled core not built")

from downstream_perception.sim.depth_camera import (  # noqa: E402
    DepthCamera,
    circle_poses,
    look_at,
    room_scene,
)
from downstream_perception.tsdf_eval import observed_samples, score_mesh  # noqa: E402


def lesson_tsdf() -> dp.Tsdf:
    c = dp.TsdfConfig()
    c.voxel_size_m = 1.0
    c.truncation_voxels = 4.0
    c.behind_surface_dropoff = False
    c.max_weight = 0.0
    c.max_depth_m = 100.0
    return dp.Tsdf(c)


def test_lesson_fusion_table() -> None:
    tsdf = lesson_tsdf()
    tsdf.integrate_points(np.array([[4.5, 0.0, 0.0]]), np.zeros(3))
    tsdf.integrate_points(np.array([[5.5, 0.0, 0.0]]), np.zeros(3))
    x = np.arange(3.0, 8.0)
    distance, weight = tsdf.sample(np.stack([x, 0 * x, 0 * x], 1))
    # sample() returns metres: the lesson's D times mu = 4.
    np.testing.assert_allclose(distance / 4.0, [0.5, 0.25, 0.0, -0.25, -0.5], atol=1e-6)
    np.testing.assert_array_equal(weight, 2.0)


def camera(c: DepthCamera) -> dp.PinholeCamera:
    return dp.PinholeCamera(c.fx, c.fy, c.cx, c.cy, c.width, c.height)


def test_millimetre_and_metre_depth_agree() -> None:
    cam = DepthCamera()
    pose = look_at(np.array([1.2, 0.3, 1.5]), np.array([0.0, 0.0, 0.6]))
    depth = cam.render(room_scene(), pose)
    millimetres = np.nan_to_num(np.rint(depth * 1000.0), nan=0.0).astype(np.uint16)
    a, b = dp.Tsdf(), dp.Tsdf()
    # The same float32 conversion as the core's (mm * 0.001f), so both fuse identical depths.
    metres = np.where(millimetres > 0, millimetres.astype(np.float32) * np.float32(0.001), np.nan)
    sa = a.integrate_depth(metres.astype(np.float32), camera(cam), pose)
    sb = b.integrate_depth(millimetres, camera(cam), pose)
    assert sa.pixels_valid == sb.pixels_valid > 0
    assert sa.voxels_updated == sb.voxels_updated
    probe = np.array([[0.8, 0.6, 0.7], [0.0, 0.0, 0.05]])
    np.testing.assert_allclose(a.sample(probe)[0], b.sample(probe)[0], atol=1e-6, equal_nan=True)


def test_bad_input_is_refused_with_a_reason() -> None:
    tsdf = dp.Tsdf()
    cam = DepthCamera()
    with pytest.raises(ValueError, match="depth must be"):
        tsdf.integrate_depth(np.ones((10, 10), np.float32), camera(cam), np.eye(4))
    with pytest.raises(ValueError, match="orthonormal"):
        tsdf.integrate_depth(
            np.ones((240, 320), np.float32), camera(cam), 2 * np.eye(4) - np.diag([0, 0, 0, 1])
        )
    with pytest.raises(ValueError, match="float"):
        tsdf.integrate_depth(np.ones((240, 320), np.int64), camera(cam), np.eye(4))
    with pytest.raises(ValueError, match="focal"):
        dp.PinholeCamera(float("nan"), 1.0, 0.0, 0.0, 10, 10)
    bad = dp.TsdfConfig()
    bad.voxel_size_m = 0.0
    with pytest.raises(ValueError, match="voxel_size_m"):
        dp.Tsdf(bad)
    # NaN / 0 / +Inf depths are counted, not fused.
    depth = np.full((240, 320), np.nan, np.float32)
    depth[0, :10] = 0.0
    depth[1, :5] = np.inf
    stats = tsdf.integrate_depth(depth, camera(cam), np.eye(4))
    assert (stats.pixels_valid, stats.pixels_no_return) == (0, 5)
    assert stats.pixels_invalid == 240 * 320 - 5
    assert tsdf.block_count == 0


@pytest.fixture(scope="module")
def room_frames() -> tuple:
    scene, cam = room_scene(), DepthCamera()
    poses = circle_poses(30)
    depths = [cam.render(scene, T) for T in poses]
    return scene, cam, poses, depths, observed_samples(scene, cam, poses, depths)


@pytest.mark.parametrize("voxel", [0.02, 0.05])
def test_room_mesh_accuracy(room_frames: tuple, voxel: float, tmp_path: Path) -> None:
    scene, cam, poses, depths, observed = room_frames
    config = dp.TsdfConfig()
    config.voxel_size_m = voxel
    tsdf = dp.Tsdf(config)
    for pose, depth in zip(poses, depths, strict=True):
        tsdf.integrate_depth(depth, camera(cam), pose)
    assert tsdf.update_mesh() == tsdf.block_count
    mesh = tsdf.mesh()
    score = score_mesh(scene, mesh["vertices"], mesh["triangles"], voxel, observed)
    print(voxel, score.row())
    # Anchors at 320 x 240 (Open3D legacy / bias-corrected tensor): 2 cm 0.88 / 0.62 mm mean,
    # 0.34 / 0.17 % ghosts, 0.997 / 0.936 complete; 5 cm 2.90 mm, 1.51 %, 0.983. Issue 5's goal:
    # <= 0.4 mm, < 0.05 % ghosts, >= 0.997 complete. Measured here: 2 cm 0.28 mm, 0.044 %,
    # 0.9976; 5 cm 0.63 mm, 0.26 %, 0.945 (this room's walls lie on the 5 cm lattice and
    # marching cubes chamfers its concave edges by up to a voxel; walls off the lattice: 0.984).
    if voxel == 0.02:
        assert score.mean_error_m < 0.0004
        assert score.completeness >= 0.997
        assert score.ghost_fraction < 0.0005
    else:
        assert score.mean_error_m < 0.0015
        assert score.completeness > 0.94
        assert score.ghost_fraction < 0.005
    # Normals point into free space: stepping along them increases the true distance.
    step = scene.signed_distance(mesh["vertices"] + 0.5 * voxel * mesh["normals"])
    assert np.mean(step > scene.signed_distance(mesh["vertices"])) > 0.95
    path = tmp_path / "room.ply"
    tsdf.write_ply(str(path))
    header = path.read_bytes().split(b"end_header\n")[0].decode()
    assert f"element vertex {len(mesh['vertices'])}" in header
    assert f"element face {len(mesh['triangles'])}" in header


def test_depth_camera_renders_exact_depths() -> None:
    # Looking straight down from 2 m at the floor (z = 0) of an empty room: depth 2 everywhere
    # the floor is seen, and the true signed distance of the hit points is 0.
    from downstream_perception.sim.depth_camera import Scene3D

    scene = Scene3D(room_min=(-10, -10, 0), room_max=(10, 10, 5))
    cam = DepthCamera()
    pose = look_at(
        np.array([0.0, 0.0, 2.0]), np.array([0.0, 0.0, 0.0]), up=np.array([0.0, 1.0, 0.0])
    )
    depth = cam.render(scene, pose)
    np.testing.assert_allclose(depth, 2.0, rtol=1e-6)
    rays = cam.rays() * depth.reshape(-1, 1)
    hits = rays @ pose[:3, :3].T + pose[:3, 3]
    np.testing.assert_allclose(scene.signed_distance(hits), 0.0, atol=1e-6)
