"""pytest: Python bindings of the costmap features (footprint cells, decay, point clouds,
moving scans), each checked against an independent numpy computation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import downstream_perception as dp


def test_footprint_cells_match_a_numpy_point_in_polygon() -> None:
    geometry = dp.GridGeometry(80, 60, 0.05, -2.0, -1.5)
    polygon = [(0.4, 0.25), (-0.3, 0.25), (-0.3, -0.25), (0.4, -0.25)]
    pose = (0.3, -0.2, 0.7)
    mask = dp.footprint_cells(polygon, pose, geometry)
    assert mask.shape == (60, 80)
    # Independent check: rotate every cell centre into the robot frame, test the rectangle.
    ys, xs = np.indices(mask.shape)
    cx = -2.0 + (xs + 0.5) * 0.05 - pose[0]
    cy = -1.5 + (ys + 0.5) * 0.05 - pose[1]
    c, s = math.cos(pose[2]), math.sin(pose[2])
    bx, by = c * cx + s * cy, -s * cx + c * cy
    inside = (bx > -0.3) & (bx < 0.4) & (by > -0.25) & (by < 0.25)
    on_edge = np.isclose(np.abs(bx - 0.05), 0.35, atol=1e-9) | np.isclose(
        np.abs(by), 0.25, atol=1e-9
    )
    assert np.array_equal(mask & ~on_edge, inside & ~on_edge)
    assert abs(int(mask.sum()) - 0.7 * 0.5 / 0.05**2) < 10
    with pytest.raises(ValueError):
        dp.footprint_cells([(0.0, 0.0), (1.0, 0.0)], pose, geometry)


def test_decay_is_exponential_toward_unknown() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(3, 1, 0.05, 0.0, 0.0), dp.LogOddsConfig())
    grid.set_log_odds(np.array([[8.0, -8.0, 2.2]]))
    changed = grid.decay(math.exp(-1.0))
    values = grid.log_odds()[0]
    np.testing.assert_allclose(values[:2], [8.0 / math.e, -8.0 / math.e], atol=2 / 1024)
    assert changed == 1  # 2.2 -> 0.81: occupied -> unknown
    with pytest.raises(ValueError):
        grid.decay(1.5)


def test_cloud_height_band_marks_only_obstacles() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(100, 100, 0.05, -2.5, -2.5), dp.LogOddsConfig())
    integrator = dp.ScanIntegrator(dp.ScanIntegratorConfig())
    pose = np.eye(4)
    pose[2, 3] = 0.4  # sensor 0.4 m above the grid plane
    points = np.array(
        [[1.025, 0.025, 0.0], [-1.025, 0.025, -0.38]],  # an obstacle at z 0.4, a floor point
        dtype=np.float32,
    )
    for _ in range(4):
        stats = integrator.integrate_cloud(grid, points, pose, 0.1, 1.5)
    assert stats.points_outside_height == 1
    states = grid.states()
    assert states[50, 70] == 1  # (1.025, 0.025) occupied
    assert states[50, 29] == -1  # the floor point's cell never marked
    with pytest.raises(ValueError):
        integrator.integrate_cloud(grid, points[:, :2], pose)
    with pytest.raises(ValueError):
        integrator.integrate_cloud(grid, points, pose, 1.0, 0.5)


def test_moving_scan_lands_on_the_wall() -> None:
    n = 101
    angle_min, inc = -0.5, 0.01
    yaws = np.linspace(0.0, 0.2, n)
    ranges = (2.025 / np.cos(yaws + angle_min + np.arange(n) * inc)).astype(np.float32)
    config = dp.ScanIntegratorConfig()
    config.obstacle_max_range = 5.0
    config.raytrace_max_range = 5.0
    integrator = dp.ScanIntegrator(config)
    corrected = dp.LogOddsGrid(dp.GridGeometry(100, 100, 0.05, -2.5, -2.5), dp.LogOddsConfig())
    rigid = dp.LogOddsGrid(dp.GridGeometry(100, 100, 0.05, -2.5, -2.5), dp.LogOddsConfig())
    for _ in range(3):
        integrator.integrate_moving(
            corrected, ranges, angle_min, inc, 0.05, 30.0, (0, 0, 0), (0, 0, 0.2)
        )
        integrator.integrate(rigid, ranges, angle_min, inc, 0.05, 30.0, (0.0, 0.0, 0.0))
    wall_col = int((2.025 + 2.5) / 0.05)
    occupied_cols = np.nonzero((corrected.states() == 1).any(axis=0))[0]
    assert set(occupied_cols.tolist()) == {wall_col}
    rigid_cols = np.nonzero((rigid.states() == 1).any(axis=0))[0]
    assert len(rigid_cols) > 1  # the smear the correction removes
