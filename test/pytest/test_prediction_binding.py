"""pytest: predicted track footprints through the bindings: the lesson's forklift corridor, and
the swept shape against an independent numpy rasterisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import downstream_perception as dp


def point_config() -> dp.PredictionConfig:
    config = dp.PredictionConfig()
    config.prediction_horizon_s = 1.5
    config.uncertainty_sigmas = 0.0
    return config


def test_lesson_forklift_corridor() -> None:
    grid = dp.GridGeometry(400, 200, 0.05, 0.0, 0.0)
    forklift = dp.PlanarTrack([8.0186, 4.0921], [-0.6, 0.0])
    cells = dp.predicted_cells(forklift, 0.0, point_config(), grid)
    assert sorted(map(tuple, cells.tolist())) == [(x, 81) for x in range(142, 161)]
    costs = np.zeros((200, 400), dtype=np.uint8)
    costs[cells[:, 1], cells[:, 0]] = dp.LETHAL_OBSTACLE
    inflation = dp.InflationConfig()
    inflation.inflation_radius = 0.40
    inflation.inscribed_radius = 0.20
    inflation.cost_scaling_factor = 3.0
    inflated = dp.inflate(costs, 0.05, inflation)
    columns = np.flatnonzero(inflated[81])
    assert (columns[0], columns[-1]) == (134, 168)
    assert (columns[-1] - columns[0]) * 0.05 == pytest.approx(1.70)  # the 34-cell corridor


def rasterise(polygon: np.ndarray, grow: float, grid: dp.GridGeometry) -> set[tuple[int, int]]:
    """Cells whose centre is within `grow` of a convex CCW polygon, by brute force in numpy."""
    xs = grid.origin_x + (np.arange(grid.size_x) + 0.5) * grid.resolution
    ys = grid.origin_y + (np.arange(grid.size_y) + 0.5) * grid.resolution
    px, py = np.meshgrid(xs, ys)
    a = polygon
    b = np.roll(polygon, -1, axis=0)
    inside = np.ones_like(px, dtype=bool)
    nearest = np.full_like(px, np.inf)
    for (ax, ay), (bx, by) in zip(a, b, strict=True):
        inside &= (bx - ax) * (py - ay) - (by - ay) * (px - ax) >= 0
        dx, dy = bx - ax, by - ay
        t = np.clip(((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy), 0, 1)
        nearest = np.minimum(nearest, np.hypot(px - ax - t * dx, py - ay - t * dy))
    covered = inside | (nearest <= grow)
    yy, xx = np.nonzero(covered)
    return set(zip(xx.tolist(), yy.tolist(), strict=True))


def test_swept_box_with_uncertainty_matches_numpy() -> None:
    grid = dp.GridGeometry(160, 160, 0.05, 0.0, 0.0)
    config = dp.PredictionConfig()
    config.prediction_horizon_s = 1.0
    config.uncertainty_sigmas = 2.0
    track = dp.PlanarTrack(
        [2.0, 3.0],
        [1.2, 0.9],
        np.diag([0.004, 0.002]),
        np.diag([0.01, 0.01]),
        size_x=0.8,
        size_y=0.5,
        box_yaw=math.radians(30),
    )
    age = 0.25
    polygon = dp.swept_polygon(track, age + 1.0, config)
    assert polygon.shape == (6, 2)  # a box moving off its axes sweeps a hexagon
    grow = dp.uncertainty_radius(track, age + 1.0, config)
    sigma = np.diag([0.004, 0.002]) + (age + 1.0) ** 2 * np.diag([0.01, 0.01])
    assert grow == pytest.approx(2.0 * math.sqrt(np.linalg.eigvalsh(sigma).max()))
    expected = rasterise(polygon, grow, grid)
    got = set(map(tuple, dp.predicted_cells(track, age, config, grid).tolist()))
    # The centre path's cells are inside the swept box anyway: the sets agree exactly.
    assert got == expected
    assert len(got) > 100


def test_bad_tracks_are_refused_and_fast_ones_give_no_cells() -> None:
    grid = dp.GridGeometry(100, 100, 0.05, 0.0, 0.0)
    config = dp.PredictionConfig()
    nan_track = dp.PlanarTrack([math.nan, 1.0], [0.0, 0.0])
    assert nan_track.validate() != ""
    with pytest.raises(ValueError, match="position is not finite"):
        dp.predicted_cells(nan_track, 0.0, config, grid)
    fast = dp.PlanarTrack([1.0, 1.0], [100.0, 0.0])  # beyond max_speed_mps: valid, not swept
    assert dp.predicted_cells(fast, 0.0, config, grid).shape == (0, 2)
    config.prediction_horizon_s = -1.0
    assert "prediction_horizon_s" in config.validate()


def test_recent_cells_cover_where_the_object_was_not_where_it_goes() -> None:
    grid = dp.GridGeometry(160, 160, 0.05, 0.0, 0.0)
    track = dp.PlanarTrack([4.0, 4.0], [0.5, 0.0], size_x=0.6, size_y=0.4, box_yaw=0.3)
    lookback, age, margin = 0.4, 0.2, 0.1
    cells = set(map(tuple, dp.recent_cells(track, lookback, age, margin, 5.0, grid).tolist()))
    # The same as the box grown by the margin, swept from 0.4 s before the stamp to 0.2 s after,
    # rasterised independently: the hull of the grown box at both ends.
    c, s = math.cos(0.3), math.sin(0.3)
    hx, hy = 0.3 + margin, 0.2 + margin
    corners = []
    for dt in (-lookback, age):
        cx, cy = 4.0 + 0.5 * dt, 4.0
        corners += [(cx + c * a - s * b, cy + s * a + c * b) for a in (-hx, hx) for b in (-hy, hy)]
    polygon = convex_hull(np.array(corners))
    assert cells == rasterise(polygon, 0.0, grid)
    # Nothing beyond where the object is now (the prediction's business, not the clearing's).
    front = 4.0 + 0.5 * age + c * hx + s * hy
    assert max(x for x, _ in cells) * 0.05 <= front
    with pytest.raises(ValueError, match="lookback_s"):
        dp.recent_cells(track, -1.0, age, margin, 5.0, grid)


def convex_hull(points: np.ndarray) -> np.ndarray:
    """Counter-clockwise hull (Andrew's monotone chain), for the test's own rasterisation."""
    pts = sorted(map(tuple, points.tolist()))

    def half(seq: list[tuple[float, float]]) -> list[tuple[float, float]]:
        out: list[tuple[float, float]] = []
        for p in seq:
            while len(out) >= 2 and (
                (out[-1][0] - out[-2][0]) * (p[1] - out[-2][1])
                - (out[-1][1] - out[-2][1]) * (p[0] - out[-2][0])
                <= 0
            ):
                out.pop()
            out.append(p)
        return out

    lower, upper = half(pts), half(pts[::-1])
    return np.array(lower[:-1] + upper[:-1])


def test_invalid_inputs_raise_value_error_with_the_reason() -> None:
    # Issue 17 item 8: the helpers skipped validate(): a NaN polygon and a negative radius came out.
    grid = dp.GridGeometry(40, 40, 0.1, 0.0, 0.0)
    good = dp.PlanarTrack([2.0, 2.0], [0.5, 0.0], size_x=0.5, size_y=0.4)
    nan_size = dp.PlanarTrack([2.0, 2.0], [0.5, 0.0], size_x=math.nan, size_y=0.4)
    negative_cap = dp.PredictionConfig()
    negative_cap.max_uncertainty_m = -1.0
    reversed_sizes = dp.PredictionConfig()
    reversed_sizes.min_object_size_m = 2.0
    reversed_sizes.max_object_size_m = 1.0
    with pytest.raises(ValueError, match="size or orientation"):
        dp.swept_polygon(nan_size, 1.0, dp.PredictionConfig())
    with pytest.raises(ValueError, match="min_object_size_m"):
        dp.swept_polygon(good, 1.0, reversed_sizes)
    with pytest.raises(ValueError, match="max_uncertainty_m"):
        dp.uncertainty_radius(good, 1.0, negative_cap)
    with pytest.raises(ValueError, match="time"):
        dp.swept_polygon(good, math.inf, dp.PredictionConfig())
    with pytest.raises(ValueError, match="max_uncertainty_m"):
        dp.predicted_cells(good, 0.0, negative_cap, grid)
    with pytest.raises(ValueError, match="size or orientation"):
        dp.predicted_cells(nan_size, 0.0, dp.PredictionConfig(), grid)
    with pytest.raises(ValueError, match="lookback_s"):
        dp.recent_cells(good, -1.0, 0.0, 0.1, 5.0, grid)
    with pytest.raises(ValueError, match="size or orientation"):
        dp.recent_cells(nan_size, 0.1, 0.0, 0.1, 5.0, grid)
    # Valid inputs still give finite results.
    assert np.isfinite(dp.swept_polygon(good, 1.0, dp.PredictionConfig())).all()
    assert dp.uncertainty_radius(good, 1.0, dp.PredictionConfig()) >= 0.0
    assert len(dp.predicted_cells(good, 0.0, dp.PredictionConfig(), grid)) > 0
