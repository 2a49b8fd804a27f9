"""downstream_perception: pose-stamped sensor data turned into what a planner consumes.

The compiled core (``downstream_perception._core``, C++ via pybind11) provides the grid geometry,
ray traversal, the fixed-point log-odds grid, LaserScan integration with REP-117 semantics and
SE(2) helpers, with numpy arrays in and out. ``downstream_perception.sim`` is a pure-numpy world
and lidar simulator.

Example::

    import numpy as np
    import downstream_perception as dp

    grid = dp.LogOddsGrid(dp.GridGeometry(200, 200, 0.05, -5.0, -5.0))
    integrator = dp.ScanIntegrator()
    ranges = np.full(360, 2.0, dtype=np.float32)
    stats = integrator.integrate(grid, ranges, -np.pi, 2 * np.pi / 360, 0.05, 30.0, (0, 0, 0))
    print(stats.cells_cleared, stats.cells_marked, grid.states())
"""

from __future__ import annotations

from typing import Any

try:
    from downstream_perception._core import (  # noqa: F401
        FREE_SPACE,
        INSCRIBED_INFLATED_OBSTACLE,
        LETHAL_OBSTACLE,
        NO_INFORMATION,
        GridGeometry,
        InflationConfig,
        IntegrationStats,
        LogOddsConfig,
        LogOddsGrid,
        Pose2D,
        ScanIntegrator,
        ScanIntegratorConfig,
        Tracker,
        TrackerConfig,
        TrackerStats,
        TrackState,
        apply,
        bresenham_line,
        chi_square_quantile,
        compose,
        footprint_cells,
        footprint_radii,
        inflate,
        inflation_cost,
        interpolate,
        inverse,
        iou,
        log_odds_of,
        mask_iou,
        nms,
        normalize_angle,
        occupancy_table,
        probability_of,
        ray_cells,
        shortest_angular_distance,
        solve_assignment,
    )

    _CORE_IMPORT_ERROR: ImportError | None = None
except ImportError as error:  # the pure-Python parts (sim) stay usable without the build
    _CORE_IMPORT_ERROR = error


def __getattr__(name: str) -> Any:
    if _CORE_IMPORT_ERROR is not None:
        raise ImportError(
            f"downstream_perception.{name} needs the compiled core, which did not import "
            f"({_CORE_IMPORT_ERROR}). Build it with `make build` and "
            "`source .ws/devel/setup.bash`."
        ) from _CORE_IMPORT_ERROR
    raise AttributeError(f"module 'downstream_perception' has no attribute {name!r}")
