"""The inflation binding against an independent numpy reference (brute-force exact EDT)."""

from __future__ import annotations

import numpy as np
import pytest

import downstream_perception as dp


def reference(costs: np.ndarray, resolution: float, radius: float, csf: float, r_ins: float):
    lethal = np.argwhere(costs == dp.LETHAL_OBSTACLE)
    ys, xs = np.indices(costs.shape)
    d2 = np.full(costs.shape, np.inf)
    for ly, lx in lethal:
        d2 = np.minimum(d2, (ys - ly) ** 2 + (xs - lx) ** 2)
    d = np.sqrt(d2) * resolution
    with np.errstate(over="ignore", invalid="ignore"):
        decay = np.floor(252.0 * np.exp(-csf * (d - r_ins)))
    cost = np.where(d <= r_ins + 1e-12, 253, decay)
    cost = np.where(d > radius * (1 + 1e-9) + 1e-12, 0, cost)
    cost = np.where(d == 0, 254, cost)
    return np.maximum(costs, cost.astype(np.uint8))


@pytest.mark.parametrize("radius", [0.0, 0.25, 0.55, 1.2])
def test_inflate_matches_numpy_reference(radius: float) -> None:
    rng = np.random.default_rng(int(radius * 100))
    costs = np.where(rng.random((40, 57)) < 0.01, dp.LETHAL_OBSTACLE, 0).astype(np.uint8)
    costs[0, 0] = costs[-1, 30] = dp.LETHAL_OBSTACLE  # on the border
    config = dp.InflationConfig()
    config.inflation_radius = radius
    config.cost_scaling_factor = 3.0
    config.inscribed_radius = min(radius, 0.2)
    got = dp.inflate(costs, 0.05, config)
    expected = reference(costs, 0.05, radius, 3.0, config.inscribed_radius)
    np.testing.assert_array_equal(got, expected)


def test_lesson_golden_costs_and_footprint() -> None:
    config = dp.InflationConfig()
    config.cost_scaling_factor = 3.0
    config.inscribed_radius = 0.20
    config.inflation_radius = 0.60
    assert [dp.inflation_cost(n * 0.05, config) for n in (0, 4, 6, 8, 12, 13)] == [
        254,
        253,
        186,
        138,
        75,
        0,
    ]
    inscribed, circumscribed = dp.footprint_radii(
        [(0.25, 0.25), (-0.25, 0.25), (-0.25, -0.25), (0.25, -0.25)]
    )
    assert inscribed == pytest.approx(0.25)
    assert circumscribed == pytest.approx(0.353553, abs=1e-6)
    with pytest.raises(ValueError):
        dp.footprint_radii([(0.0, 0.0), (1.0, 0.0)])
    bad = dp.InflationConfig()
    bad.inflation_radius = -1.0
    with pytest.raises(ValueError):
        dp.inflate(np.zeros((3, 3), np.uint8), 0.05, bad)


@pytest.mark.parametrize("resolution", [2e-5, 5e-324])
def test_radius_of_too_many_cells_is_refused(resolution: float) -> None:
    # Issue 17 item 8: 0.55 m at 2e-5 m took 28 s per update; at 5e-324 m the cost table could not
    # be allocated. Both are refused with the bound in the message.
    config = dp.InflationConfig()
    costs = np.zeros((4, 4), np.uint8)
    costs[1, 1] = dp.LETHAL_OBSTACLE
    with pytest.raises(ValueError, match="cells"):
        dp.inflate(costs, resolution, config)
    assert "cells" in config.validate(resolution)


def test_radius_at_the_cell_limit_is_accepted() -> None:
    config = dp.InflationConfig()
    config.inflation_radius = dp.InflationConfig.MAX_RADIUS_CELLS * 0.05
    assert config.validate(0.05) == ""
    costs = np.zeros((3, 3), np.uint8)
    costs[1, 1] = dp.LETHAL_OBSTACLE
    assert dp.inflate(costs, 0.05, config)[0, 0] > 0
