"""pytest: the ESDF through Python, against scipy's exact Euclidean distance transform on the
simulated room, incrementally (a box taken away), and its interpolated distance and gradient."""

from __future__ import annotations

import numpy as np
import pytest

dp = pytest.importorskip("downstream_perception._core", reason="compiled core not built")
ndimage = pytest.importorskip("scipy.ndimage")

from downstream_perception.sim.depth_camera import (  # noqa: E402
    DepthCamera,
    Scene3D,
    circle_poses,
    room_scene,
)

VOXEL = 0.05
MAX_DISTANCE = 0.6
HEIGHTS = np.linspace(0.6, 1.8, 25)


def make_tsdf() -> dp.Tsdf:
    config = dp.TsdfConfig()
    config.voxel_size_m = VOXEL
    config.carve_free_space = True
    tsdf = dp.Tsdf(config)
    esdf = dp.EsdfConfig()
    esdf.max_distance_m = MAX_DISTANCE
    tsdf.set_esdf_config(esdf)
    return tsdf


def integrate(tsdf: dp.Tsdf, scene: Scene3D, poses: list[np.ndarray]) -> list[dp.EsdfUpdateStats]:
    cam = DepthCamera()
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    stats = []
    for pose in poses:
        tsdf.integrate_depth(cam.render(scene, pose), pinhole, pose)
        stats.append(tsdf.esdf_update())
    return stats


def oracle_mismatches(tsdf: dp.Tsdf) -> tuple[int, int]:
    """(voxels whose ESDF value differs from scipy's exact EDT of the TSDF's states, voxels
    known) over the known voxels' bounding box plus a block."""
    known = tsdf.esdf_voxels()
    lo = known["voxels"].min(axis=0) - 8
    hi = known["voxels"].max(axis=0) + 8
    shape = tuple(hi - lo + 1)
    idx = np.stack(
        np.meshgrid(*[np.arange(a, b + 1) for a, b in zip(lo, hi, strict=True)], indexing="ij"), -1
    )
    sdf, _ = tsdf.sample(idx.reshape(-1, 3) * VOXEL)
    sdf = sdf.reshape(shape)
    free = sdf >= 0.0  # NaN (unknown) is neither
    occupied = sdf < 0.0
    # Distance from each voxel to the nearest voxel of the other state (lattice units).
    to_occupied = ndimage.distance_transform_edt(~occupied)
    to_free = ndimage.distance_transform_edt(~free)
    expected = np.full(shape, np.nan, dtype=np.float32)
    expected[free] = np.minimum(MAX_DISTANCE, (to_occupied[free] - 0.5) * VOXEL)
    expected[occupied] = -np.minimum(MAX_DISTANCE, (to_free[occupied] - 0.5) * VOXEL)
    got = np.full(shape, np.nan, dtype=np.float32)
    v = known["voxels"] - lo
    got[v[:, 0], v[:, 1], v[:, 2]] = known["distance"]
    differ = ~((got == expected) | (np.isnan(got) & np.isnan(expected)))
    return int(differ.sum()), int((free | occupied).sum())


def test_incremental_esdf_matches_scipy_exact_edt_with_a_box_taken_away() -> None:
    tsdf = make_tsdf()
    poses = circle_poses(8)
    scene = room_scene()
    stats = integrate(tsdf, scene, poses)
    assert stats[0].full and not any(s.full for s in stats[1:])
    off, known = oracle_mismatches(tsdf)
    assert off == 0
    assert known > 100_000
    without_box = room_scene()
    without_box.boxes = without_box.boxes[1:]  # the table top stays
    stats = integrate(tsdf, without_box, poses)
    assert sum(s.voxels_changed for s in stats) > 1000
    assert oracle_mismatches(tsdf)[0] == 0
    # The incremental field is the one a full recomputation gives, voxel for voxel.
    incremental = tsdf.esdf_voxels()
    assert tsdf.esdf_recompute().full
    full = tsdf.esdf_voxels()
    order_i = np.lexsort(incremental["voxels"].T)
    order_f = np.lexsort(full["voxels"].T)
    np.testing.assert_array_equal(incremental["voxels"][order_i], full["voxels"][order_f])
    np.testing.assert_array_equal(incremental["distance"][order_i], full["distance"][order_f])
    # The box's centre was inside it; now it is free space.
    d, _ = tsdf.esdf_distance(np.array([[0.8073, 0.5959, 0.3529]]))
    assert d[0] > 0.0
    assert tsdf.esdf_block_count <= tsdf.block_count
    assert 0 < tsdf.esdf_memory_bytes


def test_floor_distance_and_gradient_in_a_numpy_batch() -> None:
    # The room's floor lies 2.9 mm above the voxel layer k = 0, so layers k <= 0 are occupied
    # and a free voxel k is k layers above the nearest occupied one: (k - 1/2) * 5 cm. Away from
    # everything else (0.5 m from the box, 1 m from the pole) the interpolated field is
    # d = z - 0.025 m with gradient (0, 0, 1).
    tsdf = make_tsdf()
    integrate(tsdf, room_scene(), circle_poses(8))
    points = np.array([[0.0, 0.3, 0.2], [0.013, 0.27, 0.131], [-0.11, 0.2, 0.0625]])
    d, grad = tsdf.esdf_distance(points)
    assert d.shape == (3,) and grad.shape == (3, 3)
    np.testing.assert_allclose(d, points[:, 2] - 0.025, atol=1e-6)
    np.testing.assert_allclose(grad, np.tile([0.0, 0.0, 1.0], (3, 1)), atol=1e-5)
    # Outside the map: unknown.
    d, grad = tsdf.esdf_distance(np.array([[50.0, 0.0, 1.0], [np.nan, 0.0, 0.0]]))
    assert np.isnan(d).all() and np.isnan(grad).all()


def test_esdf_config_is_checked_against_the_voxel_size() -> None:
    tsdf = make_tsdf()
    bad = dp.EsdfConfig()
    bad.max_distance_m = 0.01  # below one 5 cm voxel
    assert bad.validate(VOXEL) != ""
    with pytest.raises(ValueError, match="max_distance_m"):
        tsdf.set_esdf_config(bad)
    assert tsdf.esdf_config.max_distance_m == MAX_DISTANCE


def band_columns(tsdf: dp.Tsdf, grid: dp.GridGeometry, min_z: float, max_z: float) -> np.ndarray:
    """Column states over `grid` from the TSDF sampled at the band's voxel centres (k * voxel
    in [min_z, max_z]): 2 occupied (a voxel with D < 0), 1 free, 0 unknown; [y, x]."""
    i0 = round(grid.origin_x / VOXEL + 0.5)
    j0 = round(grid.origin_y / VOXEL + 0.5)
    ks = np.arange(int(np.ceil(min_z / VOXEL)), int(np.floor(max_z / VOXEL)) + 1)
    jj, ii, kk = np.meshgrid(
        j0 + np.arange(grid.size_y), i0 + np.arange(grid.size_x), ks, indexing="ij"
    )
    sdf, _ = tsdf.sample(np.c_[ii.ravel(), jj.ravel(), kk.ravel()] * VOXEL)
    sdf = sdf.reshape(jj.shape)
    occupied = (sdf < 0.0).any(axis=2)
    free = (sdf >= 0.0).any(axis=2)
    return np.where(occupied, 2, np.where(free, 1, 0))


def test_band_slice_is_the_2d_esdf_of_the_bands_columns_and_the_rooms_clearance() -> None:
    # The nodelet's ~slice_distance: scipy's exact EDT of the band's columns with the ESDF's
    # half voxel, equal value for value, at three bands and caps; the floor below the band is no
    # obstacle, and near objects the value is the room's true clearance.
    tsdf = make_tsdf()
    integrate(tsdf, room_scene(), circle_poses(8))
    for min_z, max_z, cap in ((0.05, 1.8, 2.0), (0.3, 0.9, 0.5), (1.0, 1.45, 0.1)):
        band = tsdf.esdf_band_slice(min_z, max_z, cap)
        grid, got = band["grid"], band["distance"]
        assert got.shape == (grid.size_y, grid.size_x) and got.dtype == np.float32
        state = band_columns(tsdf, grid, min_z, max_z)
        assert band["columns_occupied"] == int((state == 2).sum()) > 100
        assert band["columns_free"] == int((state == 1).sum()) > 1000
        to_occupied = ndimage.distance_transform_edt(state != 2)
        to_free = ndimage.distance_transform_edt(state != 1)
        expected = np.full(state.shape, np.nan, dtype=np.float32)
        expected[state == 1] = np.minimum(cap, (to_occupied[state == 1] - 0.5) * VOXEL)
        expected[state == 2] = -np.minimum(cap, (to_free[state == 2] - 0.5) * VOXEL)
        np.testing.assert_array_equal(got, expected)
    # The default band against the room: the clearance from the objects is the minimum of the
    # scene's distance over heights 0.6 .. 1.8 m (the floor is farther there than they are).
    band = tsdf.esdf_band_slice()
    grid, got = band["grid"], band["distance"]
    ys, xs = np.nonzero(got > 0.0)
    xy = np.c_[grid.origin_x + (xs + 0.5) * VOXEL, grid.origin_y + (ys + 0.5) * VOXEL]
    truth = np.min(
        [room_scene().signed_distance(np.c_[xy, np.full(len(xy), z)]) for z in HEIGHTS],
        axis=0,
    )
    # The field is a voxel field: its zero level lies halfway between an occupied and a free
    # voxel centre, the true surface anywhere in between (here the walls lie 2.9 mm off the
    # voxel centres: 0.021 m off on each of their columns).
    near = (truth > 0.1) & (truth < 0.5)
    assert near.sum() > 500
    error = np.abs(got[ys, xs][near] - truth[near])
    assert np.median(error) < 0.6 * VOXEL, np.percentile(error, [50, 90, 99])
    assert float(np.percentile(error, 90)) < 1.6 * VOXEL, np.percentile(error, [50, 90, 99])
    with pytest.raises(ValueError, match="min_z_m < max_z_m"):
        tsdf.esdf_band_slice(1.0, 0.5)
    with pytest.raises(ValueError, match="max_distance_m"):
        tsdf.esdf_band_slice(0.05, 1.8, 0.0)


def whole_in(whole: dict, grid: dp.GridGeometry) -> np.ndarray:
    """The whole map's band ESDF (esdf_band_slice without a grid) over the cells of `grid`."""
    g0 = whole["grid"]
    x0 = round((grid.origin_x - g0.origin_x) / VOXEL)
    y0 = round((grid.origin_y - g0.origin_y) / VOXEL)
    return whole["distance"][y0 : y0 + grid.size_y, x0 : x0 + grid.size_x]


def test_band_slice_in_a_window_is_the_whole_maps_there() -> None:
    # Tsdf.slice_window (the nodelet's ~slice_window_m and ~slice_max_cells) and the band's ESDF
    # over it: the transform runs over the window grown by the cap and is cropped, so inside the
    # window every value equals the whole map's, also next to walls just outside it.
    tsdf = make_tsdf()
    integrate(tsdf, room_scene(), circle_poses(8))
    whole = tsdf.esdf_band_slice(max_distance_m=1.0)
    # 1 m at 5 cm: 20 columns; x = 1.63 is column 33 (floor(32.6 + 0.5)), index 10 of the
    # window: columns 23..42, origin 22.5 voxels = 1.125 m; y = -0.41: column -8, -18..1.
    grid, capped = tsdf.slice_window(1.63, -0.41, 1.0)
    assert (grid.size_x, grid.size_y, capped) == (20, 20, False)
    assert (grid.origin_x, grid.origin_y) == pytest.approx((1.125, -0.925), abs=1e-12)
    for centre, side in (((1.63, -0.41), 1.0), ((-1.9, 1.9), 1.5), ((0.0, 0.0), 0.0)):
        grid, _ = tsdf.slice_window(*centre, side)
        band = tsdf.esdf_band_slice(max_distance_m=1.0, grid=grid)
        got = band["grid"]
        assert (got.size_x, got.size_y, got.origin_x, got.origin_y) == (
            grid.size_x,
            grid.size_y,
            grid.origin_x,
            grid.origin_y,
        )
        expected = whole_in(whole, grid)
        np.testing.assert_array_equal(band["distance"], expected)
        assert band["columns_occupied"] == int((expected < 0).sum())
        assert band["columns_computed"] >= grid.size_x * grid.size_y
        assert band["voxels_in_band"] > 0
    # The cap: 100 cells cut the whole extent to the 10 x 10 square around the centre.
    grid, capped = tsdf.slice_window(1.63, -0.41, 0.0, 100)
    assert (grid.size_x, grid.size_y, capped) == (10, 10, True)
    assert grid.origin_x == pytest.approx((33 - 5 - 0.5) * VOXEL, abs=1e-12)
    # Missing every block: an empty grid, and an empty band slice over it.
    grid, _ = tsdf.slice_window(50.0, 0.0, 1.0)
    assert grid.size_x * grid.size_y == 0
    assert tsdf.esdf_band_slice(grid=grid)["distance"].size == 0
    for bad in ((0.0, 0.0, -1.0), (0.0, 0.0, float("nan")), (0.0, 0.0, 1.0, 0)):
        with pytest.raises(ValueError, match="slice window"):
            tsdf.slice_window(*bad)
    with pytest.raises(ValueError, match="lattice|voxel column"):
        tsdf.esdf_band_slice(grid=dp.GridGeometry(10, 10, VOXEL, 0.0, 0.0))


def test_band_slice_padding_is_bounded_by_max_computed_columns() -> None:
    # A 1 m window (20 x 20 columns) with a 1 m cap pads ceil(1 / 0.05 + 1/2) = 21 columns on
    # each side; at most 30 x 30 columns computed, the padding narrows to 5 and obstacles beyond
    # it are missed: a value may only grow, and equals the whole map's wherever the nearest
    # column of the other kind lies within the computed box.
    tsdf = make_tsdf()
    integrate(tsdf, room_scene(), circle_poses(8))
    whole = tsdf.esdf_band_slice(max_distance_m=1.0)
    grid, _ = tsdf.slice_window(1.63, -0.41, 1.0)
    free = tsdf.esdf_band_slice(max_distance_m=1.0, grid=grid)
    assert (free["padding_voxels"], free["padding_cut"]) == (21, False)
    band = tsdf.esdf_band_slice(max_distance_m=1.0, grid=grid, max_computed_columns=30 * 30)
    assert (band["padding_voxels"], band["padding_cut"]) == (5, True)
    assert band["columns_computed"] <= 30 * 30
    expected = whole_in(whole, grid)
    got = band["distance"]
    known = ~np.isnan(expected)
    assert known.sum() > 100
    assert np.all(np.abs(got[known]) >= np.abs(expected[known]))
    yy, xx = np.mgrid[0 : grid.size_y, 0 : grid.size_x]
    edge = np.minimum(np.minimum(xx, yy), np.minimum(grid.size_x - 1 - xx, grid.size_y - 1 - yy))
    inside = known & (np.abs(expected) / VOXEL + 0.5 <= edge + 5)
    assert inside.sum() > 10
    np.testing.assert_array_equal(got[inside], expected[inside])
