"""The Python bindings give the same numbers as the C++ golden tests."""

from __future__ import annotations

import math

import numpy as np
import pytest

dp = pytest.importorskip("downstream_perception._core", reason="compiled core not built")


def deg(d: float) -> float:
    return math.radians(d)


# ---------------------------------------------------------------------------- grid geometry
def test_world_to_cell_floors() -> None:
    g = dp.GridGeometry(100, 100, 0.25, 0.0, 0.0)
    assert g.world_to_cell(5.2, 5.0) == (20, 20)
    assert g.world_to_cell(5.25, 0.1) == (21, 0)
    h = dp.GridGeometry(10, 10, 1.0, 0.0, 0.0)
    assert h.world_to_cell(-0.5, 0.0) == (-1, 0)
    assert not h.in_bounds(-1, 0)
    with pytest.raises(ValueError, match="resolution"):
        dp.GridGeometry(10, 10, -1.0, 0.0, 0.0)


# ---------------------------------------------------------------------------- ray traversal
def test_bresenham_golden_line() -> None:
    cells = dp.bresenham_line(2, 2, 7, 5)
    assert cells.tolist() == [[2, 2], [3, 3], [4, 3], [5, 4], [6, 4], [7, 5]]


def test_extreme_inputs_stay_in_the_grid_or_are_refused() -> None:
    # Issue 17: a sensor 1e18 m away gave cells outside the grid; extreme ints overflowed.
    g = dp.GridGeometry(200, 200, 0.05, -5.0, -5.0)
    for far in (1e12, 1e18, 1e300):
        for angle in np.linspace(-math.pi, math.pi, 37):
            cells = dp.ray_cells(g, far * math.cos(angle), far * math.sin(angle), 0.12, -0.3)
            assert len(cells) > 0
            assert cells.min() >= 0 and cells.max() < 200
            assert tuple(cells[-1]) == g.world_to_cell(0.12, -0.3)
    assert len(dp.ray_cells(g, math.nan, 0.0, 1.0, 1.0)) == 0
    with pytest.raises(ValueError, match="cells"):
        dp.bresenham_line(-(2**31), 0, 2**31 - 1, 0)


def test_ray_cells_match_a_numpy_supercover_reference() -> None:
    """Every cell the segment crosses, by dense sampling in numpy, equals the C++ walk."""
    rng = np.random.default_rng(5)
    g = dp.GridGeometry(60, 60, 0.1, -3.0, -3.0)
    for _ in range(200):
        x0, y0, x1, y1 = rng.uniform(-2.9, 2.9, size=4)
        cells = dp.ray_cells(g, x0, y0, x1, y1)
        t = np.linspace(0.0, 1.0, 20001)
        px = np.floor((x0 + t * (x1 - x0) + 3.0) / 0.1).astype(int)
        py = np.floor((y0 + t * (y1 - y0) + 3.0) / 0.1).astype(int)
        sampled = {(int(a), int(b)) for a, b in zip(px, py, strict=True)}
        walked = {(int(a), int(b)) for a, b in cells}
        assert len(walked) == len(cells)  # no cell twice
        # Dense sampling can miss a cell clipped at a corner by less than a sample step, never
        # invent one: the walk contains every sampled cell.
        assert sampled <= walked
        assert len(walked - sampled) <= 2
        assert tuple(cells[-1]) == g.world_to_cell(x1, y1)


# ---------------------------------------------------------------------------- log-odds
def test_log_odds_golden_numbers() -> None:
    assert dp.log_odds_of(0.7) == pytest.approx(0.847, abs=5e-4)
    assert dp.log_odds_of(0.4) == pytest.approx(-0.405, abs=5e-4)
    grid = dp.LogOddsGrid(dp.GridGeometry(1, 1, 0.05))
    for _ in range(3):
        grid.add_hit(0, 0)
    assert grid.cell_probability(0, 0) == pytest.approx(0.927, abs=5e-4)
    grid.reset()
    for _ in range(5):
        grid.add_hit(0, 0)
    grid.add_miss(0, 0)
    grid.add_miss(0, 0)
    assert grid.cell_probability(0, 0) == pytest.approx(0.969, abs=5e-4)
    grid.reset()
    grid.add_hit(0, 0)
    grid.add_miss(0, 0)
    assert grid.cell_probability(0, 0) == pytest.approx(0.609, abs=5e-4)
    for _ in range(500):
        grid.add_hit(0, 0)
    assert grid.cell_log_odds(0, 0) == 8.0
    with pytest.raises(IndexError):
        grid.add_hit(1, 0)


def test_fixed_point_rounding_bound() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(4, 3, 0.05))
    values = np.linspace(-7.9, 7.9, 12).reshape(3, 4)
    grid.set_log_odds(values)
    assert np.max(np.abs(grid.log_odds() - values)) <= dp.LogOddsGrid.quantum / 2 + 1e-6
    assert grid.memory_bytes == 4 * 3 * 2
    with pytest.raises(ValueError):
        grid.set_log_odds(np.zeros((4, 3)))


def test_states_and_probability_arrays() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(3, 1, 0.05))
    grid.set_log_odds(np.array([[2.4, 0.0, -2.4]]))
    assert grid.states().tolist() == [[1, -1, 0]]
    assert grid.probability() == pytest.approx(np.array([[0.917, 0.5, 0.083]]), abs=5e-4)


def test_invalid_sensor_model_is_a_value_error() -> None:
    config = dp.LogOddsConfig()
    config.p_hit = 0.3
    assert "p_hit" in config.validate()
    with pytest.raises(ValueError, match="p_hit"):
        dp.LogOddsGrid(dp.GridGeometry(2, 2, 0.05), config)


# ---------------------------------------------------------------------------- scan integration
def make_integrator(**overrides: float | bool) -> dp.ScanIntegrator:
    config = dp.ScanIntegratorConfig()
    config.obstacle_max_range = 4.0
    config.raytrace_max_range = 4.47
    for key, value in overrides.items():
        setattr(config, key, value)
    return dp.ScanIntegrator(config)


def test_two_thread_clearing_gives_the_one_thread_grid() -> None:
    # A dense scan (3600 beams out to ~10 m on 400 x 400 at 5 cm: ~0.7 M ray cells, above the
    # two-thread threshold) in a room with a round pillar, from three spots, several times each.
    rng = np.random.default_rng(3)
    angles = -np.pi + np.arange(3600) * (2.0 * np.pi / 3600)
    grids = {n: dp.LogOddsGrid(dp.GridGeometry(400, 400, 0.05, -10.0, -10.0)) for n in (1, 2)}
    integrators = {
        n: make_integrator(obstacle_max_range=30.0, raytrace_max_range=30.0) for n in (1, 2)
    }
    for n, integrator in integrators.items():
        integrator.threads = n
        assert integrator.threads == n
    for k in range(12):
        sx, sy = [(0.013, 0.02), (-2.1, 1.3), (3.2, -0.7)][k % 3]
        c, s = np.cos(angles), np.sin(angles)
        with np.errstate(divide="ignore"):
            r = np.minimum(np.abs((np.sign(c) * 9.4 - sx) / c), np.abs((np.sign(s) * 9.1 - sy) / s))
        # A pillar of radius 0.6 m at (4, 4): the ray's nearer intersection, where it has one.
        fx, fy = sx - 4.0, sy - 4.0
        b = fx * c + fy * s
        disc = b * b - (fx * fx + fy * fy - 0.36)
        t = -b - np.sqrt(np.maximum(disc, 0.0))
        r = np.where((disc > 0) & (t > 0), np.minimum(r, t), r)
        ranges = (r + rng.normal(0.0, 0.01, r.shape)).astype(np.float32)
        stats = {
            n: integrators[n].integrate(
                grids[n], ranges, -np.pi, 2.0 * np.pi / 3600, 0.05, 30.0, (sx, sy, 0.0)
            )
            for n in (1, 2)
        }
        assert stats[1].cells_cleared > 200_000
        assert stats[1].cells_cleared == stats[2].cells_cleared
        assert stats[1].cells_changed == stats[2].cells_changed
        np.testing.assert_array_equal(grids[1].log_odds(), grids[2].log_odds())
    assert (grids[1].states() == 1).sum() > 1000  # walls and the pillar are occupied


def test_the_integrator_times_each_steady_walk() -> None:
    # A steady dense scene (3600 beams in a 4.4 m room, misses that saturate at once): after the
    # first scan over unseen space, the integrator measures each of its steady walks; on one
    # thread the shared (two-thread) walks never run.
    model = dp.LogOddsConfig()
    model.p_hit, model.p_miss, model.clamp_min, model.clamp_max = 0.99, 0.01, -2.1, 2.1
    grid = dp.LogOddsGrid(dp.GridGeometry(200, 200, 0.05, -5.0, -5.0), model)
    integrator = make_integrator(obstacle_max_range=30.0, raytrace_max_range=30.0)
    integrator.threads = 1
    one_thread = {"per_ray", "blocks", "reverse_query", "first_visit"}
    shared = {"per_ray_shared", "blocks_shared", "first_visit_shared"}
    assert integrator.walk_runs == dict.fromkeys(one_thread | shared, 0)
    angles = -np.pi + np.arange(3600) * (2.0 * np.pi / 3600)
    c, s = np.cos(angles), np.sin(angles)
    with np.errstate(divide="ignore"):
        r = np.minimum(np.abs(4.4 / c), np.abs(4.4 / s))
    rng = np.random.default_rng(11)
    scans = 20
    for _ in range(scans):
        ranges = (r + rng.normal(0.0, 0.01, r.shape)).astype(np.float32)
        integrator.integrate(
            grid, ranges, -np.pi, 2.0 * np.pi / 3600, 0.05, 30.0, (0.01, 0.02, 0.0)
        )
    runs = integrator.walk_runs
    assert all(runs[k] >= 2 for k in one_thread), runs
    assert all(runs[k] == 0 for k in shared), runs
    assert sum(runs.values()) <= scans - 1  # the first scan (unseen space) is not timed


def test_scan_integration_matches_the_cpp_test() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(100, 100, 0.1, -5.0, -5.0))
    stats = make_integrator().integrate(
        grid, np.array([2.05], dtype=np.float32), 0.0, 0.01, 0.05, 30.0, (0.0, 0.0, 0.0)
    )
    assert (stats.cells_marked, stats.cells_cleared) == (1, 20)
    assert stats.clear_mark_ratio() == 20.0
    lo = grid.log_odds()
    assert lo[50, 70] == pytest.approx(grid.hit_increment)
    assert np.all(lo[50, 50:70] == pytest.approx(grid.miss_increment))
    assert lo[50, 71] == 0.0
    assert stats.touched == (50, 50, 70, 50)


def test_rep117_in_python() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(100, 100, 0.1, -5.0, -5.0))
    ranges = np.array([np.nan, -np.inf, np.inf], dtype=np.float32)
    stats = make_integrator().integrate(grid, ranges, 0.0, np.pi / 2, 0.05, 30.0, (0, 0, 0))
    assert (stats.beams_invalid, stats.beams_no_return, stats.cells_marked) == (2, 1, 0)
    assert stats.cells_cleared == 46


def test_malformed_scan_raises() -> None:
    grid = dp.LogOddsGrid(dp.GridGeometry(10, 10, 0.1))
    with pytest.raises(ValueError, match="increment"):
        make_integrator().integrate(grid, np.ones(5, np.float32), 0.0, 0.0, 0.05, 30.0, (0, 0, 0))
    with pytest.raises(ValueError, match="range_min"):
        make_integrator().integrate(grid, np.ones(5, np.float32), 0.0, 0.1, 5.0, 1.0, (0, 0, 0))


# ---------------------------------------------------------------------------- SE(2)
def test_se2_golden_numbers() -> None:
    map_odom = dp.Pose2D(2.0, 1.0, deg(10))
    odom_base = dp.Pose2D(3.0, 0.0, deg(30))
    map_base = dp.compose(map_odom, odom_base)
    assert map_base.as_tuple() == pytest.approx((4.9544, 1.5209, deg(40)), abs=1e-4)
    wall = dp.apply(map_base, np.array([[4.0, 0.0]]))
    assert wall[0] == pytest.approx([8.0186, 4.0921], abs=1e-4)
    goal = dp.apply(dp.inverse(map_base), np.array([[8.0, 4.0]]))
    assert goal[0] == pytest.approx([3.9266, -0.0586], abs=1e-4)
    p = dp.interpolate(
        dp.Pose2D(4.90, 1.50, deg(38)), 1.00, dp.Pose2D(5.06, 1.62, deg(44)), 1.10, 1.06
    )
    assert p.as_tuple() == pytest.approx((4.996, 1.572, deg(41.6)), abs=1e-9)
    q = dp.interpolate(dp.Pose2D(0, 0, deg(358)), 0.0, dp.Pose2D(0, 0, deg(4)), 1.0, 0.6)
    assert q.yaw == pytest.approx(deg(1.6), abs=1e-9)


def test_occupancy_table() -> None:
    table = dp.occupancy_table()
    assert (table[0], table[253], table[254], table[255]) == (0, 99, 100, -1)
    assert np.all(np.diff(table[1:253].astype(int)) >= 0)


def test_numpy_abi_guard() -> None:
    # pybind11 < 2.12 and numpy 2 give silently wrong arrays: the package refuses that pairing.
    from downstream_perception import numpy_abi_problem

    assert numpy_abi_problem("1.24.2", (2, 10)) is None
    assert numpy_abi_problem("2.1.0", (2, 12)) is None
    problem = numpy_abi_problem("2.4.6", (2, 10))
    assert problem is not None and "pybind11 2.10" in problem and "numpy 2.4.6" in problem
