"""pytest: the TSDF core through Python, on the lesson's numbers and the simulated room."""

from __future__ import annotations

import functools
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
from downstream_perception.tsdf_eval import near_mesh, observed_samples, score_mesh  # noqa: E402


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


def test_live_settings_apply_and_the_lattice_is_fixed() -> None:
    tsdf = lesson_tsdf()
    points = np.array([[4.5, 0.0, 0.0]])
    for _ in range(4):
        tsdf.integrate_points(points, np.zeros(3))
    capped = tsdf.config
    capped.max_weight = 2.0
    tsdf.set_config(capped)
    tsdf.integrate_points(points, np.zeros(3))
    _, weight = tsdf.sample(np.array([[5.0, 0.0, 0.0]]))
    assert weight[0] == 2.0  # 4 + 1 fused, then capped by the live setting
    coarser = tsdf.config
    coarser.voxel_size_m = 2.0
    with pytest.raises(ValueError, match="fixed"):
        tsdf.set_config(coarser)
    assert tsdf.config.voxel_size_m == 1.0


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


def test_float_layouts_fuse_identically() -> None:
    # float32 C-contiguous depth is read in place, other float layouts are converted: a float64
    # copy and a Fortran-ordered float32 copy of the same frame must fuse to the same map.
    cam = DepthCamera()
    pose = look_at(np.array([1.2, 0.3, 1.5]), np.array([0.0, 0.0, 0.6]))
    depth = cam.render(room_scene(), pose).astype(np.float32)
    layouts = [depth, depth.astype(np.float64), np.asfortranarray(depth)]
    assert not layouts[2].flags.c_contiguous
    maps = [dp.Tsdf() for _ in layouts]
    updated = [
        m.integrate_depth(d, camera(cam), pose).voxels_updated
        for m, d in zip(maps, layouts, strict=True)
    ]
    assert updated[0] > 0 and updated.count(updated[0]) == 3
    probe = np.random.default_rng(3).uniform([-1.0, -1.0, 0.0], [1.5, 1.5, 1.5], size=(2000, 3))
    reference = maps[0].sample(probe)[0]
    assert np.isfinite(reference).sum() > 100
    for other in maps[1:]:
        np.testing.assert_array_equal(other.sample(probe)[0], reference)


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


@functools.cache
def room_frames(image: str) -> tuple:
    """The room's 30 frames for "qvga" or "vga", rendered once per test session."""
    cam = DepthCamera.vga() if image == "vga" else DepthCamera()
    scene = room_scene()
    poses = circle_poses(30)
    depths = [cam.render(scene, T) for T in poses]
    return cam, scene, poses, depths, observed_samples(scene, cam, poses, depths)


def fused_mesh(config: dp.TsdfConfig, cam: DepthCamera, poses: list, depths: list) -> tuple:
    """A Tsdf of `config` fused from the frames, and its mesh."""
    tsdf = dp.Tsdf(config)
    for pose, depth in zip(poses, depths, strict=True):
        tsdf.integrate_depth(depth, camera(cam), pose)
    tsdf.update_mesh()
    return tsdf, tsdf.mesh()


def scores_by_setting(
    name: str,
    values: tuple,
    cam: DepthCamera,
    scene: object,
    poses: list,
    depths: list,
    observed: np.ndarray,
) -> dict:
    """tsdf_eval scores (2 cm) of the meshes fused from the frames with TsdfConfig's `name` set to
    each of `values`, by value."""
    scores = {}
    for value in values:
        config = dp.TsdfConfig()
        setattr(config, name, value)
        _, mesh = fused_mesh(config, cam, poses, depths)
        scores[value] = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.02, observed)
    return scores


def offset_room(offset: tuple[float, float, float]) -> tuple:
    """The accuracy benchmark's room moved by `offset` (m), cameras and all: its 320x240 camera,
    the scene, the 30 poses, their depths and the samples of the surface they observe."""
    from downstream_perception.sim.scenes import accuracy_scene

    cam = DepthCamera()
    scene, poses = accuracy_scene("room", offset, 30)
    depths = [cam.render(scene, pose) for pose in poses]
    return cam, scene, poses, depths, observed_samples(scene, cam, poses, depths)


def room_tsdf_5cm() -> dp.Tsdf:
    """The room fused from its 320x240 frames at 5 cm voxels."""
    cam, _, poses, depths, _ = room_frames("qvga")
    config = dp.TsdfConfig()
    config.voxel_size_m = 0.05
    tsdf = dp.Tsdf(config)
    for pose, depth in zip(poses, depths, strict=True):
        tsdf.integrate_depth(depth, camera(cam), pose)
    return tsdf


# (image, voxel) -> (mean error m, completeness, ghost fraction) bars. Measured on this room
# (surfaces off the voxel lattice): 640x480 / 2 cm 0.29 mm, 0.9993, 0.046 %; 320x240 / 2 cm
# 0.67 mm, 0.9991, 0.046 %; 320x240 / 5 cm 1.63 mm, 0.965, 0.49 %. Issue 5's goal at 640x480 /
# 2 cm: <= 0.4 mm, >= 0.997, < 0.05 %. Open3D 0.19 legacy on the same frames (run side by side):
# 0.73 / 0.97 / 2.75 mm, 0.9994 / 0.9993 / 0.974, 0.57 / 0.53 / 1.25 %.
# Those ghost shares counted every block-seam vertex once per block (~20 % duplicates, nearly
# all on the surface); the mesh is welded since issue 22, and the same ghosts over distinct
# vertices read 0.060 % at 640x480 / 2 cm (53 of 88,923). The edge guard of issue 22 defect 4
# (near side only, planes kept, grazing relief) raised 320x240 / 2 cm from under the old bar
# of 0.06 % to 0.065 % (completeness 0.9995), hence its bar 0.07 %. Those bars hold with
# behind_surface_dropoff on (the default until 2026-12-04). The default is off since then: under
# pose noise the drop-off lost surface (docs/tsdf.md), and without it this clean room has more
# ghosts: 0.079 % (640x480 / 2 cm), 0.082 % (320x240 / 2 cm), 1.22 % (5 cm; legacy 1.25 %),
# mean error 0.31 / 0.66 / 2.03 mm, completeness 0.9996 / 0.9995 / 0.965.
BARS = {
    ("vga", 0.02, True): (0.0004, 0.997, 0.0007),
    ("qvga", 0.02, True): (0.0008, 0.997, 0.0007),
    ("qvga", 0.05, True): (0.0025, 0.95, 0.008),
    ("vga", 0.02, None): (0.0004, 0.997, 0.0009),
    ("qvga", 0.02, None): (0.0008, 0.997, 0.0009),
    ("qvga", 0.05, None): (0.0025, 0.95, 0.014),
}


@pytest.mark.parametrize(("image", "voxel", "dropoff"), list(BARS))
def test_room_mesh_accuracy(image: str, voxel: float, dropoff: bool | None, tmp_path: Path) -> None:
    """The room at each size, with the defaults (dropoff None) and with the drop-off on."""
    cam, scene, poses, depths, observed = room_frames(image)
    config = dp.TsdfConfig()
    config.voxel_size_m = voxel
    if dropoff is not None:
        config.behind_surface_dropoff = dropoff
    tsdf = dp.Tsdf(config)
    for pose, depth in zip(poses, depths, strict=True):
        tsdf.integrate_depth(depth, camera(cam), pose)
    assert tsdf.update_mesh() == tsdf.block_count
    mesh = tsdf.mesh()
    score = score_mesh(scene, mesh["vertices"], mesh["triangles"], voxel, observed)
    print(image, voxel, score.row())
    mean_bar, completeness_bar, ghost_bar = BARS[(image, voxel, dropoff)]
    health = tsdf.health()
    assert health["crossings"] > 1000
    # Projective distances from oblique views read about 1/cos of the view angle (> 1).
    assert 1.0 < health["mean_gradient_ratio"] < 2.5
    assert health["double_crossings"] < 0.05 * health["crossings"]
    assert score.mean_error_m <= mean_bar
    assert score.completeness >= completeness_bar
    assert score.ghost_fraction < ghost_bar
    # Normals point into free space: stepping along them increases the true distance.
    step = scene.signed_distance(mesh["vertices"] + 0.5 * voxel * mesh["normals"])
    assert np.mean(step > scene.signed_distance(mesh["vertices"])) > 0.95
    path = tmp_path / "room.ply"
    tsdf.write_ply(str(path))
    header = path.read_bytes().split(b"end_header\n")[0].decode()
    assert f"element vertex {len(mesh['vertices'])}" in header
    assert f"element face {len(mesh['triangles'])}" in header


def test_edge_guard_removes_ghosts() -> None:
    # Without the edge guard, rays grazing the box and table rims write "inside" values into the
    # free space beyond their edges: several times more ghost vertices.
    frames = room_frames("qvga")
    ghosts = scores_by_setting("edge_guard_rad", (0.0, 0.0075), *frames)
    assert ghosts[0.0075].ghost_fraction * 3 < ghosts[0.0].ghost_fraction
    assert ghosts[0.0075].completeness > ghosts[0.0].completeness - 0.002


def test_rim_distance_rule_and_grazing_reach_fill_the_corridor_without_ghosts() -> None:
    # Issue 22, defect 4: the corridor on the voxel lattice (its wall shelf's top and a box face
    # on planes of voxel centres, seen at grazing incidence) against the rule before it.
    from downstream_perception.sim.scenes import accuracy_scene

    cam = DepthCamera()
    scene, poses = accuracy_scene("corridor", (0.0, 0.0, 0.0), 12)
    depths = [cam.render(scene, pose) for pose in poses]
    observed = observed_samples(scene, cam, poses, depths)
    defaults = dp.TsdfConfig()
    assert defaults.edge_guard_rule == dp.TsdfEdgeGuardRule.RIM_DISTANCE
    assert (defaults.edge_guard_rim_scale, defaults.grazing_reach_voxels) == (1.0, 1.0)
    assert defaults.grazing_reach_max_voxels == 16.0
    before = dp.TsdfConfig()
    before.edge_guard_rule = dp.TsdfEdgeGuardRule.FIXED_RADIUS
    before.grazing_reach_voxels = 0.0
    scores = {}
    for name, config in (("rim", defaults), ("before", before)):
        _, mesh = fused_mesh(config, cam, poses, depths)
        scores[name] = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.02, observed)
    assert scores["rim"].completeness > scores["before"].completeness + 0.004
    assert scores["rim"].ghost_fraction <= scores["before"].ghost_fraction
    assert scores["rim"].ghost_fraction < 0.0005
    # Out-of-range settings are refused with the key's name.
    for key, value in (
        ("edge_guard_rim_scale", 0.0),
        ("grazing_reach_voxels", -1.0),
        ("grazing_reach_max_voxels", 0.5),
    ):
        bad = dp.TsdfConfig()
        setattr(bad, key, value)
        assert key in bad.validate()


@pytest.mark.parametrize("scene_name", ["clutter", "room"])
def test_rays_near_a_balls_silhouette_reach_its_depth(scene_name: str) -> None:
    # Issue 22, defect 4: a ball's lower half is seen only near its silhouette, where the rim
    # rule's plane model stopped the rays at about half the depth they can reach inside the ball
    # (0.93-0.95 of it meshed before the silhouette factor, 0.98 with it; see depth_rims.h).
    from downstream_perception.sim.scenes import accuracy_scene

    cam = DepthCamera()
    scene, poses = accuracy_scene(scene_name, (0.0, 0.0, 0.0), 12)
    depths = [cam.render(scene, pose) for pose in poses]
    observed = observed_samples(scene, cam, poses, depths)
    lower = np.zeros(len(observed), dtype=bool)
    for ball in scene.spheres:
        centre = np.asarray(ball.center)
        on_ball = np.abs(np.linalg.norm(observed - centre, axis=1) - ball.radius) < 1e-3
        lower |= on_ball & (observed[:, 2] < centre[2] - 0.3 * ball.radius)
    assert lower.sum() > 1000
    _, mesh = fused_mesh(dp.TsdfConfig(), cam, poses, depths)
    covered = near_mesh(observed[lower], mesh["vertices"], mesh["triangles"], 0.02)
    assert covered.mean() > 0.965
    score = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.02, observed)
    assert score.ghost_fraction < 0.0005


def test_unconfirmed_voxels_keep_the_table_tops_underside_clean() -> None:
    # Issue 22, defect 4: the room's 4 cm table top (mu = 8 cm) is seen only from above; deep
    # "inside" values under it meshed a skirt below its underside (0.11 % ghosts at this offset).
    # confirm_depth_voxels keeps voxels only ever seen that deep out of the mesh; sample() still
    # reads them, with a non-negative weight.
    assert dp.TsdfConfig().confirm_depth_voxels == 2.5
    offset = (0.015, 0.015, 0.015)
    cam, scene, poses, depths, observed = offset_room(offset)
    scores = {}
    for confirm in (0.0, 2.5):
        config = dp.TsdfConfig()
        config.confirm_depth_voxels = confirm
        tsdf, mesh = fused_mesh(config, cam, poses, depths)
        scores[confirm] = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.02, observed)
        # 2.5 cm under the top's underside (z 0.72 m): "inside", seen only from above the top.
        grid = np.stack(np.meshgrid(np.arange(-1.15, -0.45, 0.1), np.arange(0.45, 0.95, 0.1)), -1)
        under = np.column_stack([grid.reshape(-1, 2), np.full(grid.size // 2, 0.695)])
        distance, weight = tsdf.sample(under + np.asarray(offset))
        known = np.isfinite(distance)
        assert known.sum() >= 5 and np.any(distance[known] < 0.0)
        assert np.all(weight >= 0.0) and np.all(weight[known] > 0.0)
    assert scores[0.0].ghost_fraction > 0.0005
    assert scores[2.5].ghost_fraction < 0.0005
    assert scores[2.5].completeness > scores[0.0].completeness - 0.0005


def test_coarse_voxels_grow_no_far_side_under_the_table_top() -> None:
    # At 5 cm the 4 cm table top is thinner than a voxel: with the confirm depth at 2.5 voxels
    # (12.5 cm, no cap) the voxels under it meshed a skirt 6-10 cm below the underside (ghosts
    # over a voxel off every surface). The cap removes most of it; far_free_guess_weight (the
    # default since 2026-12-07) the rest, where frames saw those voxels far free, as a lower
    # unconfirmed_update_weight (not the default: it loses surface under large pose noise) does
    # everywhere.
    c = dp.TsdfConfig()
    assert c.confirm_depth_max_m == 0.05 and c.unconfirmed_update_weight == 1.0
    assert c.far_free_guess_weight == pytest.approx(0.05)
    assert c.confirm_depth() == pytest.approx(0.05)  # 2 cm: 2.5 voxels, under the cap
    c.voxel_size_m = 0.05
    assert c.confirm_depth() == pytest.approx(0.0625)  # the floor, 1.25 voxels, above the cap
    offset = (0.0125, 0.0125, 0.0125)
    cam, scene, poses, depths, observed = offset_room(offset)
    scores = {}
    for name, cap, weight, far_free in (
        ("before", 0.0, 1.0, 1.0),
        ("cap", 0.05, 1.0, 1.0),
        ("low", 0.05, 0.05, 1.0),
        ("default", 0.05, 1.0, 0.05),
    ):
        config = dp.TsdfConfig()
        config.voxel_size_m = 0.05
        config.confirm_depth_max_m = cap
        config.unconfirmed_update_weight = weight
        config.far_free_guess_weight = far_free
        _, mesh = fused_mesh(config, cam, poses, depths)
        scores[name] = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.05, observed)
    assert scores["before"].ghost_fraction > 0.003
    assert scores["cap"].ghost_fraction < 0.5 * scores["before"].ghost_fraction
    assert scores["low"].ghost_fraction < 0.0005
    assert scores["default"].ghost_fraction < 0.0005
    for name in ("cap", "low", "default"):
        assert scores[name].completeness > scores["before"].completeness - 0.002


def test_confirm_settings_out_of_range_are_refused() -> None:
    for name, bad in (
        ("confirm_depth_max_m", -0.01),
        ("confirm_depth_max_m", float("nan")),
        ("unconfirmed_update_weight", 0.0),
        ("unconfirmed_update_weight", 1.5),
        ("far_free_guess_weight", 0.0),
        ("far_free_guess_weight", 1.5),
    ):
        config = dp.TsdfConfig()
        setattr(config, name, bad)
        with pytest.raises(ValueError, match=name):
            dp.Tsdf(config)


def test_carving_erases_a_box_that_moved_away() -> None:
    # The room's box is seen from one pose, then removed: with carving its faces go back to free
    # space (the wall behind it is seen through where it stood), without carving they stay.
    cam = DepthCamera()
    pose = look_at(np.array([-1.0, 0.6, 0.5]), np.array([0.8, 0.6, 0.35]))  # under the table
    scene = room_scene()
    with_box = cam.render(scene, pose)
    scene.boxes = scene.boxes[1:]  # the box is gone; the table top stays
    without_box = cam.render(scene, pose)
    # On the box's front face, above the blocks the floor's band allocates (0.4 m at 5 cm).
    front_face = np.array([[0.8 - 0.3 + 0.0073, 0.6 - 0.0041, 0.6 + 0.0029]])
    distances = {}
    for carve in (False, True):
        config = dp.TsdfConfig()
        config.voxel_size_m = 0.05
        config.carve_free_space = carve
        tsdf = dp.Tsdf(config)
        for _ in range(3):
            tsdf.integrate_depth(with_box, camera(cam), pose)
        for _ in range(6):
            tsdf.integrate_depth(without_box, camera(cam), pose)
        distances[carve] = float(tsdf.sample(front_face)[0][0])
    assert np.sum(np.abs(with_box - without_box) > 0.5) > 2000  # the box filled the view
    assert abs(distances[False]) < 0.02  # m: the face is still a surface
    assert distances[True] > 0.1  # m (mu = 0.2): free


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


def test_slice_puts_the_table_top_into_the_grid() -> None:
    # The room's objects in the 0.05-1.8 m band become obstacles in a 5 cm grid, including the
    # table top (0.72-0.76 m, floating: a 2-D lidar under it would see nothing) and the sphere
    # (0.9-1.5 m); the open floor is free; outside the room is unknown.
    scene = room_scene()
    tsdf = room_tsdf_5cm()
    grid = dp.GridGeometry(100, 100, 0.05, -2.5, -2.5)
    cells = tsdf.slice(grid, 0.05, 1.8)
    assert cells.shape == (100, 100)

    def at(x: float, y: float) -> int:
        return int(cells[int((y + 2.5) / 0.05), int((x + 2.5) / 0.05)])

    table, box, sphere = scene.boxes[1].center, scene.boxes[0].center, scene.spheres[0].center
    assert at(table[0], table[1]) == 1
    assert at(box[0], box[1]) == 1
    assert at(sphere[0], sphere[1]) == 1
    assert at(0.0, 1.3) == 0  # open floor
    assert at(-2.4, -2.4) == -1  # outside the room
    # Above the table and below the sphere: the table is gone, the sphere too.
    above = tsdf.slice(grid, 0.8, 0.85)
    assert above[int((table[1] + 2.5) / 0.05), int((table[0] + 2.5) / 0.05)] == 0


def test_slice_distance_is_the_exact_euclidean_distance() -> None:
    # The room's slice at 5 cm: the clearance map equals scipy's exact Euclidean distance
    # transform of "not occupied", capped, with NaN where the slice is unknown.
    from scipy.ndimage import distance_transform_edt

    cells = room_tsdf_5cm().slice(dp.GridGeometry(100, 100, 0.05, -2.5, -2.5), 0.05, 1.8)
    distance = dp.slice_distance(cells, 0.05, 0.6)
    assert distance.shape == cells.shape and distance.dtype == np.float32
    expected = np.minimum(0.6, 0.05 * distance_transform_edt(cells != 1))
    known = cells >= 0
    assert np.isnan(distance[~known]).all()
    np.testing.assert_allclose(distance[known], expected[known], atol=1e-6)
    assert (distance[cells == 1] == 0.0).all()
    assert 0.0 < float(np.median(distance[cells == 0])) < 0.6  # free cells: some clearance
    with pytest.raises(ValueError, match="2-D"):
        dp.slice_distance(cells[0], 0.05)
    with pytest.raises(ValueError, match="max_distance_m"):
        dp.slice_distance(cells, 0.05, float("inf"))


def test_octree_lesson_log_odds_and_room() -> None:
    # One ray: the end leaf +0.847 (p_hit 0.7), a leaf on the way -0.405 (p_miss 0.4).
    tree = dp.OccupancyOctree()
    tree.insert_points(np.array([[1.01, 0.01, 0.01]]), np.array([0.01, 0.01, 0.01]))
    log_odds = tree.log_odds(np.array([[1.01, 0.01, 0.01], [0.5, 0.01, 0.01], [0.5, 1.0, 0.0]]))
    np.testing.assert_allclose(log_odds[:2], [np.log(0.7 / 0.3), np.log(0.4 / 0.6)], atol=1e-4)
    assert np.isnan(log_odds[2])
    # The room seen by the depth camera: occupied leaves lie on the true surfaces.
    cam = DepthCamera()
    scene = room_scene()
    room = dp.OccupancyOctree()
    for pose in circle_poses(10):
        room.insert_depth(cam.render(scene, pose), camera(cam), pose)
    occupied = room.occupied()
    assert len(occupied) > 1000
    # A 5 cm leaf's centre lies within half a diagonal (4.3 cm) of the surface it contains.
    assert np.percentile(np.abs(scene.signed_distance(occupied)), 99) < 0.044


def test_graceful_under_depth_and_pose_noise() -> None:
    # 5 mm depth noise and 5 mm / 0.2 deg pose noise (frames rendered at the true pose, fused at
    # the perturbed one): measured 3.3 mm mean, 0.22 % ghosts, 0.996 complete at 320x240 / 2 cm
    # (Open3D legacy on the anchors' scene: 5.6 mm, 1.34 %, 0.988).
    from downstream_perception.sim.depth_camera import perturb_pose

    cam, scene, poses, _, observed = room_frames("qvga")
    depth_rng, pose_rng = np.random.default_rng(0), np.random.default_rng(1)
    tsdf = dp.Tsdf()
    for pose in poses:
        depth = cam.render(scene, pose, depth_noise_m=0.005, rng=depth_rng)
        drifted = perturb_pose(pose, 0.005, np.deg2rad(0.2), pose_rng)
        tsdf.integrate_depth(depth, camera(cam), drifted)
    tsdf.update_mesh()
    mesh = tsdf.mesh()
    score = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.02, observed)
    assert score.mean_error_m < 0.005
    assert score.ghost_fraction < 0.005
    assert score.completeness > 0.99
    # 5 mm / 0.2 degree of pose noise is far inside mu (8 cm): no doubled shell. (Before issue
    # 22's rule, sign flicker along the surfaces counted as double crossings and rose 10-fold.)
    health = tsdf.health()
    assert health["double_crossings"] < 0.02 * health["crossings"]


def test_sample_at_a_far_or_nan_point_is_nan() -> None:
    # A far or NaN point has no voxel: NaN and weight 0, not the origin voxel's values (the
    # index used to overflow to 0).
    tsdf = lesson_tsdf()
    tsdf.integrate_points(np.array([[0.5, 0.0, 0.0]]), np.array([-3.0, 0.0, 0.0]))
    distance, weight = tsdf.sample(
        np.array([[0.0, 0.0, 0.0], [np.nan, 0.0, 0.0], [1e300, 0.0, 0.0], [0.0, -1e30, 0.0]])
    )
    assert np.isfinite(distance[0]) and weight[0] > 0.0
    assert np.isnan(distance[1:]).all()
    np.testing.assert_array_equal(weight[1:], 0.0)


def test_far_poses_and_origins_are_refused_and_counted() -> None:
    tsdf = dp.Tsdf()
    cam = DepthCamera()
    far = np.eye(4)
    far[0, 3] = 1e9
    stats = tsdf.integrate_depth(np.ones((240, 320), np.float32), camera(cam), far)
    assert stats.refused is not None and "pose" in stats.refused
    assert stats.pixels_invalid == 240 * 320
    stats = tsdf.integrate_points(np.array([[1e9 + 1.0, 0.0, 0.0]]), np.array([1e9, 0.0, 0.0]))
    assert stats.refused is not None and stats.pixels_invalid == 1
    assert tsdf.block_count == 0
    near = tsdf.integrate_depth(np.ones((240, 320), np.float32), camera(cam), np.eye(4))
    assert near.refused is None


def test_camera_with_an_absurd_principal_point_or_view_is_refused() -> None:
    with pytest.raises(ValueError, match="principal point"):
        dp.PinholeCamera(262.5, 262.5, 1e7, 119.5, 320, 240)
    with pytest.raises(ValueError, match="view too wide"):
        dp.PinholeCamera(1.0, 1.0, 159.5, 119.5, 320, 240)
    dp.PinholeCamera(262.5, 262.5, 3 * 320, -2 * 240, 320, 240)  # the bounds themselves pass


def test_lowering_max_blocks_live_evicts_down_to_the_cap() -> None:
    tsdf = room_tsdf_5cm()
    blocks = tsdf.block_count
    assert blocks > 100
    config = tsdf.config
    config.max_blocks = blocks // 5
    tsdf.set_config(config)
    assert tsdf.block_count == blocks // 5
    assert tsdf.blocks_evicted_to_cap == blocks - blocks // 5
    cam, _, poses, depths, _ = room_frames("qvga")
    stats = tsdf.integrate_depth(depths[3], camera(cam), poses[3])
    assert tsdf.block_count <= blocks // 5
    assert stats.blocks_refused > 0


def test_a_frame_without_returns_leaves_the_carved_room_as_without_it() -> None:
    # Carving, 20 frames of the room with one frame of +Inf only (no return anywhere: a failing
    # sensor) in the middle. Such a frame is no evidence of free space: it is ignored (counted)
    # and the mesh scores as without it. Measured: 1.54 mm mean error, 0.40 % ghosts either way
    # at 5 cm; letting the frame carve (fraction 0) gave 31.6 mm and 27.6 % after one good frame.
    cam, scene, poses, depths, observed = room_frames("qvga")
    poses, depths = poses[::3] + poses[1::3][:10], depths[::3] + depths[1::3][:10]
    scores = {}
    for bad_frame, fraction in ((False, 0.5), (True, 0.5), (True, 0.0)):
        config = dp.TsdfConfig()
        config.voxel_size_m = 0.05
        config.carve_free_space = True
        config.no_return_carve_min_valid_fraction = fraction
        tsdf = dp.Tsdf(config)
        for k, (pose, depth) in enumerate(zip(poses, depths, strict=True)):
            tsdf.integrate_depth(depth, camera(cam), pose)
            if bad_frame and k == 9:
                stats = tsdf.integrate_depth(np.full_like(depth, np.inf), camera(cam), pose)
                ignored = stats.pixels_no_return_ignored
                assert ignored == (depth.size if fraction > 0 else 0)
        tsdf.update_mesh()
        mesh = tsdf.mesh()
        scores[(bad_frame, fraction)] = score_mesh(
            scene, mesh["vertices"], mesh["triangles"], 0.05, observed
        )
    clean, guarded, unguarded = scores[(False, 0.5)], scores[(True, 0.5)], scores[(True, 0.0)]
    assert abs(guarded.mean_error_m - clean.mean_error_m) < 1e-5
    assert abs(guarded.ghost_fraction - clean.ghost_fraction) < 1e-4
    assert guarded.completeness >= clean.completeness - 1e-4
    assert unguarded.ghost_fraction > clean.ghost_fraction + 0.01  # the frame did carve


def test_octree_maintenance_bounds_the_tree_around_the_sensor() -> None:
    cam = DepthCamera()
    scene = room_scene()
    config = dp.OctreeConfig()
    config.max_distance_m = 1.5
    tree = dp.OccupancyOctree(config)
    poses = circle_poses(6)
    for pose in poses:
        tree.insert_depth(cam.render(scene, pose), camera(cam), pose)
    origin = poses[-1][:3, 3]
    done = tree.maintain(origin)
    assert done["nodes_evicted_by_distance"] > 0
    assert done["leaves"] == tree.leaf_count and done["memory_bytes"] == tree.memory_bytes
    occupied = tree.occupied()
    assert len(occupied) > 100
    assert np.linalg.norm(occupied - origin, axis=1).max() <= 1.5
    assert tree.evict_farther_than(origin, 0.5) > 0
    assert np.linalg.norm(tree.occupied() - origin, axis=1).max(initial=0.0) <= 0.5
    assert tree.node_count > 0


@pytest.mark.parametrize("offset", [(0.0, 0.0, 0.0), (0.0073, -0.0041, 0.0029)])
def test_double_crossings_rise_with_pose_noise_on_and_off_the_lattice(
    offset: tuple[float, float, float],
) -> None:
    # Issue 22 defect 3: on the lattice-aligned room the clean map used to show more double
    # crossings (38,107) than the one with pose noise (13,330), and a NaN mean gradient.
    from downstream_perception.sim.depth_camera import perturb_pose

    cam, scene, rng = DepthCamera(), room_scene(offset), np.random.default_rng(3)
    config = dp.TsdfConfig()
    config.voxel_size_m = 0.02
    clean, noisy = dp.Tsdf(config), dp.Tsdf(config)
    for pose in circle_poses(20):
        depth = cam.render(scene, pose)
        clean.integrate_depth(depth, camera(cam), pose)
        noisy.integrate_depth(depth, camera(cam), perturb_pose(pose, 0.02, 0.01, rng))
    good, bad = clean.health(), noisy.health()
    assert good["crossings"] > 10_000 and bad["crossings"] > 10_000
    assert bad["double_crossings"] > 3 * good["double_crossings"]
    assert good["double_crossings"] < 0.02 * good["crossings"]
    assert np.isfinite(good["mean_gradient_ratio"]) and np.isfinite(bad["mean_gradient_ratio"])


def test_the_incidence_window_keeps_the_table_top_clean_under_depth_noise() -> None:
    # With 5 mm of depth noise the incidences from a pixel's own neighbours scatter (p99 error of
    # the cosine 0.4 on a plane), so updates deep under the table top looked shallow and
    # confirmed its skirt again (0.11 % ghosts on the benchmark's frames). The plane of an
    # 11 x 11 window (incidence_window_radius_px 5) removes it without costing surface.
    assert dp.TsdfConfig().incidence_window_radius_px == 5
    cam, scene, poses, clean, observed = offset_room((0.015, 0.015, 0.015))
    rng = np.random.default_rng(5)
    noisy = [(d + rng.normal(0.0, 0.005, d.shape)).astype(np.float32) for d in clean]
    scores = scores_by_setting(
        "incidence_window_radius_px", (0, 5), cam, scene, poses, noisy, observed
    )
    assert scores[0].ghost_fraction > 0.0005
    assert scores[5].ghost_fraction < 0.0005
    assert scores[5].completeness > scores[0].completeness - 0.0005
    config = dp.TsdfConfig()
    config.incidence_window_radius_px = 65
    with pytest.raises(ValueError, match="incidence_window_radius_px"):
        dp.Tsdf(config)


def test_room_corners_on_voxel_centres_keep_their_corners() -> None:
    # The accuracy room on the lattice (walls and floor on planes of 5 cm voxel centres): read
    # across its corners by the two planes meeting there (depth_windows.h), not by the bilinear
    # chord, nearer than both, which fused the corner voxels negative and cut every corner off a
    # voxel wide: completeness 0.942 then (Open3D legacy on the same frames: 0.959), 0.975 now.
    cam, scene, poses, depths, observed = offset_room((0.0, 0.0, 0.0))
    config = dp.TsdfConfig()
    config.voxel_size_m = 0.05
    _, mesh = fused_mesh(config, cam, poses, depths)
    score = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.05, observed)
    assert score.completeness > 0.965
    assert score.ghost_fraction < 0.005


def test_noisy_room_corners_are_found_along_their_lines() -> None:
    # The same room under 5 mm of Gaussian depth noise (three seeds): each window's own kinks
    # drown in the noise, so its corners are found by the slope change summed over six lines
    # along them (depth_windows.h) and read by their planes. Measured with seeds 0, 1, 2: 0.9625,
    # 0.9634, 0.9627 (without the sums 0.9503, 0.9516, 0.9510; Open3D legacy 0.9620 on the
    # bench's noisy frames of this case); ghosts 0.17-0.20 % either way.
    cam, scene, poses, depths, observed = offset_room((0.0, 0.0, 0.0))
    config = dp.TsdfConfig()
    config.voxel_size_m = 0.05
    for seed in (0, 1, 2):
        rng = np.random.default_rng(seed)
        noisy = [(d + rng.normal(0.0, 0.005, d.shape)).astype(np.float32) for d in depths]
        _, mesh = fused_mesh(config, cam, poses, noisy)
        score = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.05, observed)
        assert score.completeness > 0.957, seed
        assert score.ghost_fraction < 0.005, seed


@pytest.mark.parametrize("offset_voxels", [0.0, 0.75])
def test_mesh_extrapolation_reaches_edges_live_and_mesh_only(offset_voxels: float) -> None:
    """mesh_extrapolate_voxels (2 by default) fills missing voxels next to the surface, so
    the 5 cm room's mesh reaches the edges the edge guard stopped short of: more of the observed
    surface within 2 cm, without more ghosts. Set live, it re-extracts every block; the TSDF it
    meshes is the same (mesh only)."""
    assert dp.TsdfConfig().mesh_extrapolate_voxels == 2.0
    offset = (offset_voxels * 0.05,) * 3
    cam, scene, poses, depths, observed = offset_room(offset)
    config = dp.TsdfConfig()
    config.voxel_size_m = 0.05
    config.mesh_extrapolate_voxels = 0.0
    tsdf, mesh = fused_mesh(config, cam, poses, depths)
    off = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.05, observed)
    probe = observed[::50]
    before = tsdf.sample(probe)
    config.mesh_extrapolate_voxels = 2.0
    tsdf.set_config(config)
    assert tsdf.update_mesh() == tsdf.block_count
    mesh = tsdf.mesh()
    on = score_mesh(scene, mesh["vertices"], mesh["triangles"], 0.05, observed)
    # Measured (offsets 0 / 3/4): completeness 0.9749 -> 0.9805 / 0.9793 -> 0.9858, ghosts
    # 0.189 -> 0.187 % / 0.326 -> 0.318 %, mean error 0.56 / 1.19-1.20 mm.
    assert on.completeness > off.completeness + 0.005
    assert on.ghost_fraction < off.ghost_fraction + 0.0002
    assert on.mean_error_m < off.mean_error_m + 0.0002
    after = tsdf.sample(probe)
    np.testing.assert_array_equal(before[0], after[0])
    np.testing.assert_array_equal(before[1], after[1])
    config.mesh_extrapolate_voxels = 64.5  # beyond its range
    with pytest.raises(ValueError, match="mesh_extrapolate_voxels"):
        tsdf.set_config(config)
    config.mesh_extrapolate_voxels = 2.0
    config.truncation_voxels = 1.5  # the default reaches farther: still a valid configuration
    assert dp.Tsdf(config).config.mesh_extrapolate_voxels == 2.0
