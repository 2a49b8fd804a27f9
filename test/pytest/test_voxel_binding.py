"""pytest: the 3-D voxel obstacle map through Python: the exact traversal's hand-worked rays, a
simulated depth camera under a table (the top stays lethal, the space under it is seen free),
and refusals of invalid input."""

from __future__ import annotations

import math

import numpy as np
import pytest

dp = pytest.importorskip("downstream_perception._core", reason="compiled core not built")

from downstream_perception.sim.depth_camera import Box, DepthCamera, Scene3D, look_at  # noqa: E402

LETHAL, FREE, UNKNOWN = 254, 0, 255
RES = 0.05


def test_voxel_ray_hand_worked() -> None:
    # The space diagonal through the corners (1,1,1) and (2,2,2): the three diagonal voxels only.
    cells = dp.voxel_ray((10, 10, 10), (0.5, 0.5, 0.5), (2.5, 2.5, 2.5))
    assert cells.tolist() == [[0, 0, 0], [1, 1, 1], [2, 2, 2]]
    assert cells.dtype == np.int32
    # Without the end voxel; a ray missing the box; a NaN end.
    assert dp.voxel_ray((10, 10, 10), (0.5, 0.5, 0.5), (2.5, 0.5, 0.5), False).tolist() == [
        [0, 0, 0],
        [1, 0, 0],
    ]
    assert dp.voxel_ray((4, 4, 4), (-1, -1, 9), (9, 9, 9)).shape == (0, 3)
    assert dp.voxel_ray((4, 4, 4), (1, 1, 1), (math.nan, 1, 1)).shape == (0, 3)


def room_config() -> dp.VoxelMapConfig:
    c = dp.VoxelMapConfig()
    c.resolution_m = RES
    c.z_resolution_m = RES
    c.z_voxels = 40  # 0 .. 2 m
    c.min_obstacle_height_m = 0.1
    c.max_obstacle_height_m = 1.9
    return c


def rays() -> dp.VoxelRayConfig:
    r = dp.VoxelRayConfig()
    r.obstacle_max_range_m = 4.0
    r.raytrace_max_range_m = 4.0
    r.no_return_range_m = 4.0
    return r


def test_table_top_stays_lethal_while_the_floor_under_it_is_seen() -> None:
    # A table top 0.8 x 0.8 m at 0.725 .. 0.775 m, centred at (0.8, 0); the room is 4 x 4 x 3 m.
    scene = Scene3D(boxes=[Box((0.8, 0.0, 0.75), (0.4, 0.4, 0.025))])
    cam = DepthCamera()
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    vmap = dp.VoxelMap(room_config(), -2.0, -2.0, 80, 80)
    # Once from a mast (1.8 m) looking down at the top, then 10 frames from 0.3 m under it.
    mast = look_at(np.array([-0.6, 0.0, 1.8]), np.array([0.8, 0.0, 0.75]))
    stats = vmap.integrate_depth(cam.render(scene, mast), pinhole, mast, 0.0, rays())
    assert stats["marked"] > 0 and stats["cleared"] > 0 and stats["dropped_updates"] == 0
    low = look_at(np.array([-0.6, 0.0, 0.3]), np.array([0.8, 0.0, 0.1]))
    for k in range(1, 11):
        vmap.integrate_depth(cam.render(scene, low), pinhole, low, float(k), rays())
    costs = vmap.project(10.0)
    assert costs.shape == (80, 80)
    # Columns of the table's inner part (x 0.5 .. 1.1, y -0.3 .. 0.3): lethal.
    inner = costs[(40 - 6) : (40 + 6), (40 + 10) : (40 + 22)]
    assert (inner == LETHAL).all()
    # Under the top's centre (x 0.80 .. 0.85, z 0.20 .. 0.25 m), on the low camera's way to the
    # far wall's foot: free, while the top's voxel (z 0.75 .. 0.80, voxel 15) above it is occupied.
    assert vmap.state(56, 40, 4, 10.0) == 0
    assert vmap.state(56, 40, 15, 10.0) == 1
    # The floor voxel itself is occupied in 3-D, below the band: no effect on the costmap.
    assert vmap.band == (2, 37)
    # In front of the table (x -0.2, y 0) the rays crossed the band: not lethal.
    occupied, _, cost = vmap.column(36, 40, 10.0)
    assert occupied == 0 and cost != LETHAL
    # The voxel cloud: every occupied centre inside the window.
    centres = vmap.occupied_centres(10.0)
    assert centres.shape[1] == 3 and len(centres) > 100
    assert (centres[:, :2] >= -2.0).all() and (centres[:, :2] <= 2.0).all()
    assert vmap.memory_bytes >= vmap.blocks * 6144


def test_invalid_input_is_refused() -> None:
    c = room_config()
    c.z_resolution_m = math.nan
    assert "z_resolution_m" in c.validate()
    with pytest.raises(ValueError, match="z_resolution_m"):
        dp.VoxelMap(c, 0.0, 0.0, 10, 10)
    with pytest.raises(ValueError, match="window"):
        dp.VoxelMap(room_config(), 0.0, 0.0, 0, 10)
    vmap = dp.VoxelMap(room_config(), 0.0, 0.0, 10, 10)
    with pytest.raises(ValueError, match="origin"):
        vmap.integrate((math.nan, 0, 0), np.zeros((0, 3)), np.zeros((0, 3)), 0.0, rays())
    with pytest.raises(TypeError):
        vmap.integrate((0, 0, 0), np.zeros((4, 2)), np.zeros((0, 3)), 0.0, rays())
    hits = np.array([[math.nan, 0.2, 0.2], [0.3, 0.2, 0.2]])
    s = vmap.integrate((0.05, 0.2, 0.2), hits, np.zeros((0, 3)), 0.0, rays())
    assert s["invalid_points"] == 1 and s["marked"] == 1
    # One hit: ln(0.7 / 0.3) = 0.8473.
    assert vmap.log_odds(6, 4, 4, 0.0) == pytest.approx(math.log(7 / 3), abs=1e-6)
    with pytest.raises(IndexError):
        vmap.log_odds(10, 0, 0, 0.0)


@pytest.mark.parametrize("clearing_mode", ["ray", "frustum"])
def test_frustum_and_ray_clearing_agree_on_the_table(clearing_mode: str) -> None:
    # The same table top and camera path through both clearing modes: the top stays lethal, the
    # space under it (seen by the low camera) is free, and a box that was there and is gone is
    # cleared in both.
    table = Box((0.8, 0.0, 0.75), (0.4, 0.4, 0.025))
    # x 1.5 .. 1.7, y 0.5 .. 0.7, z 0 .. 0.3: beside the table, well inside the mast's view (a
    # voxel is judged by its centre in frustum mode: one straddling the image border is cleared
    # only once its centre is in view).
    gone = Box((1.6, 0.6, 0.15), (0.1, 0.1, 0.15))
    cam = DepthCamera()
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    vmap = dp.VoxelMap(room_config(), -2.0, -2.0, 80, 80)
    mast = look_at(np.array([-0.6, 0.0, 1.8]), np.array([0.8, 0.0, 0.75]))
    with_box = Scene3D(boxes=[table, gone])
    vmap.integrate_depth(
        cam.render(with_box, mast), pinhole, mast, 0.0, rays(), False, 1, clearing_mode
    )
    box_column = (72, 52)  # x 1.60 .. 1.65, y 0.60 .. 0.65
    assert vmap.project(0.0)[box_column[1], box_column[0]] == LETHAL
    low = look_at(np.array([-0.6, 0.0, 0.3]), np.array([0.8, 0.0, 0.1]))
    scene = Scene3D(boxes=[table])
    for k in range(1, 11):
        view = mast if k % 2 else low
        vmap.integrate_depth(
            cam.render(scene, view), pinhole, view, float(k), rays(), False, 1, clearing_mode
        )
    costs = vmap.project(10.0)
    assert (costs[(40 - 6) : (40 + 6), (40 + 10) : (40 + 22)] == LETHAL).all()
    assert vmap.state(56, 40, 4, 10.0) == 0  # under the top
    assert vmap.state(56, 40, 15, 10.0) == 1  # the top
    assert costs[box_column[1], box_column[0]] != LETHAL  # the box is gone


def test_unknown_clearing_mode_is_refused() -> None:
    cam = DepthCamera()
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    vmap = dp.VoxelMap(room_config(), -2.0, -2.0, 80, 80)
    depth = np.ones((cam.height, cam.width), dtype=np.float32)
    with pytest.raises(ValueError, match="clearing_mode"):
        vmap.integrate_depth(depth, pinhole, np.eye(4), 0.0, rays(), False, 1, "cone")


def test_costmap2d_defaults_keep_untouched_columns_unknown() -> None:
    # costmap_2d VoxelLayer's defaults (10 voxels of 0.2 m, unknown_threshold 15): its 16-bit
    # column counts 6 bits that never become known, so an untouched column is unknown (16 > 15)
    # and one known voxel makes it free.
    c = dp.VoxelMapConfig()
    c.resolution_m = 0.1
    vmap = dp.VoxelMap(c, 0.0, 0.0, 20, 20)
    assert (vmap.project(0.0) == UNKNOWN).all()
    # A horizontal ray at 0.1 m along row y 5 from x 0.05 to a return at x 1.05.
    vmap.integrate([0.05, 0.55, 0.1], np.array([[1.05, 0.55, 0.1]]), np.zeros((0, 3)), 0.0, rays())
    costs = vmap.project(0.0)
    assert costs[5, :10].tolist() == [FREE] * 10
    assert costs[5, 10] == LETHAL
    assert vmap.column(5, 5, 0.0) == (0, 9, FREE)
    assert (np.delete(costs, 5, axis=0) == UNKNOWN).all()


def test_clear_columns_frees_the_band_under_a_footprint() -> None:
    vmap = dp.VoxelMap(room_config(), 0.0, 0.0, 40, 40)
    # Two obstacles in the band at columns (10, 10) and (12, 10), one above the band.
    hits = np.array([[0.525, 0.525, 0.5], [0.625, 0.525, 0.5], [0.525, 0.525, 1.95]])
    vmap.integrate([0.525, 0.525, 1.0], hits, np.zeros((0, 3)), 0.0, rays())
    assert vmap.project(0.0)[10, 10] == LETHAL and vmap.project(0.0)[10, 12] == LETHAL
    stats = vmap.clear_columns(np.array([[10, 10], [-5, 3], [10**12, 0]]), 1.0)
    assert stats["cleared"] == 36  # band voxels 2..37 of column (10, 10)
    costs = vmap.project(1.0)
    assert costs[10, 10] == FREE and costs[10, 12] == LETHAL
    assert vmap.state(10, 10, 39, 1.0) == 1  # above the band: kept
    assert vmap.clear_columns(np.array([[10, 10]]), 2.0)["cleared"] == 0
    with pytest.raises(ValueError):
        vmap.clear_columns(np.zeros((3, 3), dtype=np.int64), 0.0)
