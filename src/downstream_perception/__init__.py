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

import numpy as np


def numpy_abi_problem(numpy_version: str, pybind11_version: tuple[int, int]) -> str | None:
    """Why the compiled core cannot work with this numpy, or None.

    pybind11 before 2.12 reads numpy's array descriptors with numpy 1's layout; under numpy 2
    its arrays come out silently wrong (every row a copy of the first), so refuse instead.
    The build (tools/python_venv.sh) uses pybind11 2.13 from PyPI, which works with numpy 1 and
    2; the refusal only fires for a build that fell back to Debian 12's pybind11 2.10.
    """
    if int(numpy_version.split(".")[0]) >= 2 and tuple(pybind11_version) < (2, 12):
        return (
            f"the compiled core was built with pybind11 {pybind11_version[0]}."
            f"{pybind11_version[1]}, which cannot exchange arrays with numpy {numpy_version} "
            "(needs pybind11 >= 2.12); use Debian's /usr/bin/python3 (numpy 1.x) or a venv "
            "with numpy<2"
        )
    return None


try:
    from downstream_perception import _core

    _problem = numpy_abi_problem(np.__version__, tuple(_core.pybind11_version))
    if _problem is not None:
        raise ImportError(_problem)
    from downstream_perception._core import (  # noqa: F401
        FREE_SPACE,
        INSCRIBED_INFLATED_OBSTACLE,
        LETHAL_OBSTACLE,
        NO_INFORMATION,
        CorrectionMonitor,
        CorrectionMonitorConfig,
        EsdfConfig,
        EsdfUpdateStats,
        GridGeometry,
        InflationConfig,
        IntegrationStats,
        LogOddsConfig,
        LogOddsGrid,
        OccupancyOctree,
        OctreeConfig,
        PinholeCamera,
        PlanarTrack,
        Pose2D,
        PredictionConfig,
        ScanIntegrator,
        ScanIntegratorConfig,
        SeamLimits,
        StaticMap,
        StaticMapConfig,
        Tracker,
        TrackerConfig,
        TrackerStats,
        TrackState,
        Tsdf,
        TsdfConfig,
        TsdfEdgeGuardRule,
        TsdfIntegrationStats,
        TsdfWeighting,
        VoxelMap,
        VoxelMapConfig,
        VoxelRayConfig,
        apply,
        bresenham_line,
        chi_square_quantile,
        compose,
        expected_smear,
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
        predicted_cells,
        probability_of,
        ray_cells,
        recent_cells,
        shortest_angular_distance,
        slice_distance,
        solve_assignment,
        static_map_values,
        swept_polygon,
        uncertainty_radius,
        voxel_ray,
    )

    _CORE_IMPORT_ERROR: ImportError | None = None
except ImportError as error:  # the pure-Python parts (sim) stay usable without the build
    _CORE_IMPORT_ERROR = error


def __getattr__(name: str) -> Any:
    if _CORE_IMPORT_ERROR is not None:
        hint = (
            " Build it with `make build` and `source .ws/devel/setup.bash`."
            if isinstance(_CORE_IMPORT_ERROR, ModuleNotFoundError)
            else ""
        )
        raise ImportError(
            f"downstream_perception.{name} needs the compiled core, which did not import "
            f"({_CORE_IMPORT_ERROR}).{hint}"
        ) from _CORE_IMPORT_ERROR
    raise AttributeError(f"module 'downstream_perception' has no attribute {name!r}")
