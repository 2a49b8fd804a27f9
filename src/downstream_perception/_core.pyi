"""
downstream_perception ROS-free core (C++), with numpy arrays in and out.
"""

from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing

__all__: list[str] = [
    "CorrectionMonitor",
    "CorrectionMonitorConfig",
    "EsdfConfig",
    "EsdfUpdateStats",
    "FREE_SPACE",
    "GridGeometry",
    "INSCRIBED_INFLATED_OBSTACLE",
    "InflationConfig",
    "IntegrationStats",
    "LETHAL_OBSTACLE",
    "LogOddsConfig",
    "LogOddsGrid",
    "NO_INFORMATION",
    "OccupancyOctree",
    "OctreeConfig",
    "PinholeCamera",
    "PlanarTrack",
    "Pose2D",
    "PredictionConfig",
    "ScanIntegrator",
    "ScanIntegratorConfig",
    "SeamLimits",
    "StaticMap",
    "StaticMapConfig",
    "TrackState",
    "Tracker",
    "TrackerConfig",
    "TrackerStats",
    "Tsdf",
    "TsdfConfig",
    "TsdfIntegrationStats",
    "TsdfWeighting",
    "VoxelMap",
    "VoxelMapConfig",
    "VoxelRayConfig",
    "apply",
    "bresenham_line",
    "chi_square_quantile",
    "compose",
    "expected_smear",
    "footprint_cells",
    "footprint_radii",
    "inflate",
    "inflation_cost",
    "interpolate",
    "inverse",
    "iou",
    "log_odds_of",
    "mask_iou",
    "nms",
    "normalize_angle",
    "occupancy_table",
    "predicted_cells",
    "probability_of",
    "pybind11_version",
    "ray_cells",
    "recent_cells",
    "shortest_angular_distance",
    "slice_distance",
    "solve_assignment",
    "static_map_values",
    "swept_polygon",
    "uncertainty_radius",
    "voxel_ray",
]

class GridGeometry:
    """
    Grid placement: size in cells, resolution (m), origin (m) of the lower-left corner. Arrays are indexed [y, x].
    """
    def __init__(
        self,
        size_x: typing.SupportsInt | typing.SupportsIndex,
        size_y: typing.SupportsInt | typing.SupportsIndex,
        resolution: typing.SupportsFloat | typing.SupportsIndex,
        origin_x: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        origin_y: typing.SupportsFloat | typing.SupportsIndex = 0.0,
    ) -> None: ...
    def __repr__(self) -> str: ...
    def cell_centre(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> tuple[float, float]:
        """
        World coordinates (m) of the centre of cell (x, y).
        """
    def in_bounds(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> bool:
        """
        Whether cell (x, y) lies inside the grid.
        """
    def world_to_cell(
        self,
        arg0: typing.SupportsFloat | typing.SupportsIndex,
        arg1: typing.SupportsFloat | typing.SupportsIndex,
    ) -> tuple[int, int]:
        """
        Cell (x, y) containing the point, by floor; may lie outside the grid.
        """
    @property
    def origin_x(self) -> float: ...
    @property
    def origin_y(self) -> float: ...
    @property
    def resolution(self) -> float: ...
    @property
    def size_x(self) -> int: ...
    @property
    def size_y(self) -> int: ...

class Pose2D:
    """
    A 2-D pose (x, y in metres, yaw in radians, REP-103): child frame in parent frame.
    """
    def __init__(
        self,
        x: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        y: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        yaw: typing.SupportsFloat | typing.SupportsIndex = 0.0,
    ) -> None: ...
    def __repr__(self) -> str: ...
    def as_tuple(self) -> tuple[float, float, float]:
        """
        (x, y, yaw) as a tuple.
        """
    @property
    def x(self) -> float: ...
    @x.setter
    def x(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def y(self) -> float: ...
    @y.setter
    def y(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def yaw(self) -> float: ...
    @yaw.setter
    def yaw(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class OctreeConfig:
    """
    Parameters of the OctoMap occupancy octree (metres, probabilities, bytes).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def depth_stride_px(self) -> int: ...
    @depth_stride_px.setter
    def depth_stride_px(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_distance_m(self) -> float: ...
    @max_distance_m.setter
    def max_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_memory_bytes(self) -> int: ...
    @max_memory_bytes.setter
    def max_memory_bytes(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_range_m(self) -> float: ...
    @max_range_m.setter
    def max_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prob_hit(self) -> float: ...
    @prob_hit.setter
    def prob_hit(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prob_miss(self) -> float: ...
    @prob_miss.setter
    def prob_miss(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def resolution_m(self) -> float: ...
    @resolution_m.setter
    def resolution_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class PinholeCamera:
    """
    Pinhole intrinsics (pixels), ROS optical convention.
    """
    def __init__(
        self,
        fx: typing.SupportsFloat | typing.SupportsIndex,
        fy: typing.SupportsFloat | typing.SupportsIndex,
        cx: typing.SupportsFloat | typing.SupportsIndex,
        cy: typing.SupportsFloat | typing.SupportsIndex,
        width: typing.SupportsInt | typing.SupportsIndex,
        height: typing.SupportsInt | typing.SupportsIndex,
    ) -> None: ...
    @property
    def cx(self) -> float: ...
    @property
    def cy(self) -> float: ...
    @property
    def fx(self) -> float: ...
    @property
    def fy(self) -> float: ...
    @property
    def height(self) -> int: ...
    @property
    def width(self) -> int: ...

class OccupancyOctree:
    """
    OctoMap occupancy (octomap::OcTree) from the same observations.
    """
    def __init__(self, config: OctreeConfig = ...) -> None: ...
    def clear(self) -> None:
        """
        Forgets every node.
        """
    def evict_farther_than(
        self,
        center: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
        distance_m: typing.SupportsFloat | typing.SupportsIndex,
    ) -> int:
        """
        Deletes the leaves whose centre is farther than distance_m from center; returns the number of nodes deleted.
        """
    def insert_depth(
        self,
        depth: typing.Annotated[numpy.typing.ArrayLike, numpy.float32],
        camera: PinholeCamera,
        T_map_camera: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"],
    ) -> None:
        """
        Inserts a depth image (m, (height, width)) seen by `camera` at the given pose.
        """
    def insert_points(
        self,
        points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"],
        origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
    ) -> None:
        """
        Inserts an (N, 3) point cloud (m) seen from `origin`: rays cleared, end points marked.
        """
    def log_odds(
        self, points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]
    ) -> numpy.typing.NDArray[numpy.float64]:
        """
        Log-odds of the leaf at each point (NaN where never observed).
        """
    def maintain(
        self, sensor_origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]
    ) -> dict:
        """
        Applies the config's max_distance_m and max_memory_bytes around the sensor and prunes; returns what it deleted and the size after.
        """
    def occupied(self) -> numpy.typing.NDArray[numpy.float64]:
        """
        Centres (N, 3) of the occupied leaves.
        """
    def write_binary(self, path: str) -> None:
        """
        Writes the octree as an OctoMap .bt file (refuses to overwrite unless asked).
        """
    @property
    def leaf_count(self) -> int: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def node_count(self) -> int: ...

class TsdfWeighting:
    """
    Members:

      CONSTANT

      INVERSE_SQUARE_DEPTH
    """

    CONSTANT: typing.ClassVar[TsdfWeighting]
    INVERSE_SQUARE_DEPTH: typing.ClassVar[TsdfWeighting]
    __members__: typing.ClassVar[dict[str, TsdfWeighting]]
    @typing.overload
    def __eq__(self, other: TsdfWeighting) -> bool: ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool: ...
    def __getstate__(self) -> int: ...
    def __hash__(self) -> int: ...
    def __index__(self) -> int: ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    def __int__(self) -> int: ...
    @typing.overload
    def __ne__(self, other: TsdfWeighting) -> bool: ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool: ...
    def __repr__(self) -> str: ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    def __str__(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def value(self) -> int: ...

class TsdfConfig:
    """
    Parameters of the sparse TSDF (voxel size and truncation in metres, weights, memory bounds).
    """

    behind_surface_dropoff: bool
    carve_free_space: bool
    interpolate_depth: bool
    weighting: TsdfWeighting
    def __init__(self) -> None: ...
    def truncation(self) -> float:
        """
        mu in metres
        """
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def edge_guard_rad(self) -> float: ...
    @edge_guard_rad.setter
    def edge_guard_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_block_distance_m(self) -> float: ...
    @max_block_distance_m.setter
    def max_block_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_blocks(self) -> int: ...
    @max_blocks.setter
    def max_blocks(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_depth_m(self) -> float: ...
    @max_depth_m.setter
    def max_depth_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_weight(self) -> float: ...
    @max_weight.setter
    def max_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_depth_m(self) -> float: ...
    @min_depth_m.setter
    def min_depth_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_weight(self) -> float: ...
    @min_weight.setter
    def min_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def no_return_carve_min_valid_fraction(self) -> float: ...
    @no_return_carve_min_valid_fraction.setter
    def no_return_carve_min_valid_fraction(
        self, arg0: typing.SupportsFloat | typing.SupportsIndex
    ) -> None: ...
    @property
    def truncation_voxels(self) -> float: ...
    @truncation_voxels.setter
    def truncation_voxels(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def voxel_size_m(self) -> float: ...
    @voxel_size_m.setter
    def voxel_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class TsdfIntegrationStats:
    """
    What one TSDF integration did: pixels by kind, blocks touched, allocated, refused, evicted, voxels updated.
    """
    @property
    def blocks_allocated(self) -> int: ...
    @property
    def blocks_evicted(self) -> int: ...
    @property
    def blocks_refused(self) -> int: ...
    @property
    def blocks_touched(self) -> int: ...
    @property
    def pixels_invalid(self) -> int: ...
    @property
    def pixels_no_return(self) -> int: ...
    @property
    def pixels_no_return_ignored(self) -> int: ...
    @property
    def pixels_valid(self) -> int: ...
    @property
    def refused(self) -> typing.Any:
        """
        Why the whole frame was refused (its pixels counted invalid), or None.
        """
    @property
    def voxels_updated(self) -> int: ...

class Tsdf:
    """
    Sparse TSDF (8^3-voxel blocks) with an incremental marching-cubes mesher.
    """
    def __init__(self, config: TsdfConfig = ...) -> None: ...
    def clear(self) -> None:
        """
        Forgets every block, the mesh and the ESDF.
        """
    def esdf_distance(
        self, points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]
    ) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        Signed distance (N,) in m and its gradient (N, 3) at points (N, 3), trilinear between the 8 voxel centres around each point; NaN where one of them is unknown. As of the last esdf_update.
        """
    def esdf_recompute(self) -> EsdfUpdateStats:
        """
        Recomputes the whole ESDF.
        """
    def esdf_update(self) -> EsdfUpdateStats:
        """
        Brings the ESDF up to date with the map: recomputes only within max_distance_m of voxels whose state (unknown / free / occupied) changed since the last update.
        """
    def esdf_voxels(self) -> dict:
        """
        Every known ESDF voxel: dict of voxels (N, 3) int32 lattice indices (centre = index * voxel_size_m), distance (N,) float32 m, occupied (N,) int8.
        """
    def health(self) -> dict:
        """
        The lesson's health check: at zero crossings |grad (D mu)| (1 = clean), the share below 0.5, and double crossings within mu (pose drift's fingerprint).
        """
    def integrate_depth(
        self,
        depth: numpy.ndarray,
        camera: PinholeCamera,
        T_map_camera: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"],
    ) -> TsdfIntegrationStats:
        """
        Fuses a depth image: float32 metres (NaN/0 invalid, +Inf no return) or uint16 millimetres (0 invalid), T_map_camera a 4 x 4 pose of the optical frame.
        """
    def integrate_points(
        self,
        points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"],
        origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
    ) -> TsdfIntegrationStats:
        """
        Fuses points (N, 3) in the map frame seen from origin (3,).
        """
    def mesh(self) -> dict:
        """
        The mesh as of the last update_mesh(): dict of vertices (V, 3) float32 m, normals (V, 3), triangles (T, 3) uint32.
        """
    def sample(
        self, points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]
    ) -> tuple[numpy.typing.NDArray[numpy.float64], numpy.typing.NDArray[numpy.float64]]:
        """
        Signed distance (m, NaN where unobserved) and weight of the voxel nearest each point.
        """
    def set_config(self, config: TsdfConfig) -> None:
        """
        Replaces the settings that keep the voxel lattice (weights, depth limits, edge guard, memory bounds; a lower max_blocks evicts the least recently updated blocks at once); raises ValueError for an invalid config or another voxel_size_m or truncation_voxels.
        """
    def set_esdf_config(self, config: EsdfConfig) -> None:
        """
        Raises ValueError if invalid; the next esdf_update is full.
        """
    def slice(
        self,
        grid: GridGeometry,
        min_z_m: typing.SupportsFloat | typing.SupportsIndex = 0.05,
        max_z_m: typing.SupportsFloat | typing.SupportsIndex = 1.8,
        occupied_distance_m: typing.SupportsFloat | typing.SupportsIndex = -1.0,
    ) -> numpy.typing.NDArray[numpy.int8]:
        """
        2-D slice over grid ([y, x] int8: 1 occupied, 0 free, -1 unknown): a cell is occupied when a voxel in the height band (m) over it is within occupied_distance_m of a surface or inside (default one voxel).
        """
    def update_mesh(self) -> int:
        """
        Re-extracts the blocks changed since the last call; returns how many.
        """
    def write_ply(self, path: str) -> None:
        """
        Writes the welded mesh as a PLY file.
        """
    @property
    def block_count(self) -> int: ...
    @property
    def blocks_evicted_to_cap(self) -> int:
        """
        Blocks evicted because set_config lowered max_blocks below the block count (total).
        """
    @property
    def config(self) -> TsdfConfig: ...
    @property
    def esdf_block_count(self) -> int: ...
    @property
    def esdf_config(self) -> EsdfConfig:
        """
        The ESDF's settings (EsdfConfig's defaults until set_esdf_config).
        """
    @property
    def esdf_memory_bytes(self) -> int:
        """
        Bytes held by the ESDF's blocks, hash table and scratch.
        """
    @property
    def memory_bytes(self) -> int: ...

class EsdfConfig:
    """
    Parameters of the Euclidean signed distance field computed from the TSDF (metres).
    """
    def __init__(self) -> None: ...
    def validate(self, voxel_size_m: typing.SupportsFloat | typing.SupportsIndex) -> str:
        """
        Empty string if valid for TSDF voxels of voxel_size_m (m), else the reason.
        """
    @property
    def max_distance_m(self) -> float:
        """
        distances are clamped at this (m); also a change's reach
        """
    @max_distance_m.setter
    def max_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class EsdfUpdateStats:
    """
    What one ESDF update did: full or incremental, regions, voxels changed.
    """
    @property
    def blocks_read(self) -> int: ...
    @property
    def blocks_removed(self) -> int: ...
    @property
    def blocks_written(self) -> int: ...
    @property
    def full(self) -> bool: ...
    @property
    def region_voxels(self) -> int: ...
    @property
    def regions(self) -> int: ...
    @property
    def voxels_changed(self) -> int: ...

class LogOddsConfig:
    """
    Inverse sensor model and thresholds of the log-odds obstacle grid (probabilities, log-odds).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if valid, else the reason.
        """
    @property
    def clamp_max(self) -> float: ...
    @clamp_max.setter
    def clamp_max(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def clamp_min(self) -> float: ...
    @clamp_min.setter
    def clamp_min(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def free_threshold(self) -> float: ...
    @free_threshold.setter
    def free_threshold(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def occupied_threshold(self) -> float: ...
    @occupied_threshold.setter
    def occupied_threshold(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def p_hit(self) -> float: ...
    @p_hit.setter
    def p_hit(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def p_miss(self) -> float: ...
    @p_miss.setter
    def p_miss(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class LogOddsGrid:
    """
    Fixed-point log-odds occupancy grid (2 bytes per cell, quantum 1/1024).
    """

    quantum: typing.ClassVar[float] = 0.0009765625
    def __init__(self, geometry: GridGeometry, config: LogOddsConfig = ...) -> None: ...
    def add_hit(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> float:
        """
        Adds one hit (l_hit) to cell (x, y).
        """
    def add_miss(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> float:
        """
        Adds one miss (l_miss) to cell (x, y).
        """
    def cell_log_odds(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> float:
        """
        The log-odds of cell (x, y).
        """
    def cell_probability(
        self,
        arg0: typing.SupportsInt | typing.SupportsIndex,
        arg1: typing.SupportsInt | typing.SupportsIndex,
    ) -> float:
        """
        The occupancy probability of cell (x, y).
        """
    def decay(self, factor: typing.SupportsFloat | typing.SupportsIndex) -> int:
        """
        Every cell's log-odds times factor in [0, 1] (exp(-dt / tau)), rounded toward zero. Returns how many cells changed state.
        """
    def log_odds(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        (size_y, size_x) float32 log-odds.
        """
    def max_abs_log_odds(self) -> float:
        """
        Largest |log-odds| over the grid (health metric: at the clamp, never beyond).
        """
    def probability(self) -> numpy.typing.NDArray[numpy.float32]:
        """
        (size_y, size_x) float32 P(occupied).
        """
    def reset(self) -> None:
        """
        All cells back to unknown (log-odds 0).
        """
    def set_log_odds(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> None:
        """
        Sets every cell's log-odds from a (size_y, size_x) array (clamped, quantised).
        """
    def shift(
        self,
        dx: typing.SupportsInt | typing.SupportsIndex,
        dy: typing.SupportsInt | typing.SupportsIndex,
    ) -> None:
        """
        Moves the grid's origin by (dx, dy) whole cells (rolling window); cells that come into view are unknown.
        """
    def states(self) -> numpy.typing.NDArray[numpy.int8]:
        """
        (size_y, size_x) int8: -1 unknown, 0 free, 1 occupied (by the thresholds).
        """
    @property
    def config(self) -> LogOddsConfig: ...
    @property
    def geometry(self) -> GridGeometry: ...
    @property
    def hit_increment(self) -> float: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def miss_increment(self) -> float: ...

class ScanIntegratorConfig:
    """
    Ranges (m) and REP-117 options of the scan integrator (costmap_2d's obstacle-source keys).
    """

    clearing: bool
    inf_is_valid: bool
    marking: bool
    range_max_is_no_return: bool
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def obstacle_max_range(self) -> float: ...
    @obstacle_max_range.setter
    def obstacle_max_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def obstacle_min_range(self) -> float: ...
    @obstacle_min_range.setter
    def obstacle_min_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def raytrace_max_range(self) -> float: ...
    @raytrace_max_range.setter
    def raytrace_max_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def raytrace_min_range(self) -> float: ...
    @raytrace_min_range.setter
    def raytrace_min_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class IntegrationStats:
    """
    What one scan integration did: beams by kind, cells cleared, marked and changed, touched and changed windows.
    """
    def clear_mark_ratio(self) -> float:
        """
        Cells cleared per cell marked (the phantom-wall diagnostic; healthy >> 1).
        """
    @property
    def beams(self) -> int: ...
    @property
    def beams_beyond_obstacle_range(self) -> int: ...
    @property
    def beams_invalid(self) -> int: ...
    @property
    def beams_marked(self) -> int: ...
    @property
    def beams_no_return(self) -> int: ...
    @property
    def cells_changed(self) -> int: ...
    @property
    def cells_cleared(self) -> int: ...
    @property
    def cells_marked(self) -> int: ...
    @property
    def changed(self) -> tuple: ...
    @property
    def points_merged(self) -> int: ...
    @property
    def points_outside_height(self) -> int: ...
    @property
    def touched(self) -> tuple:
        """
        (min_x, min_y, max_x, max_y) inclusive, or () if nothing was touched
        """

class ScanIntegrator:
    """
    Integrates laser scans (ranges in metres) into a LogOddsGrid: hits first, then each cell cleared at most once per scan.
    """
    def __init__(self, config: ScanIntegratorConfig = ...) -> None: ...
    def integrate(
        self,
        grid: LogOddsGrid,
        ranges: typing.Annotated[numpy.typing.ArrayLike, numpy.float32],
        angle_min: typing.SupportsFloat | typing.SupportsIndex,
        angle_increment: typing.SupportsFloat | typing.SupportsIndex,
        range_min: typing.SupportsFloat | typing.SupportsIndex,
        range_max: typing.SupportsFloat | typing.SupportsIndex,
        sensor_pose: tuple[
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
        ],
    ) -> IntegrationStats:
        """
        Integrates one LaserScan (REP-117 semantics) taken at sensor_pose = (x, y, yaw) in the grid frame. Raises ValueError for a malformed scan header.
        """
    def integrate_cloud(
        self,
        grid: LogOddsGrid,
        points: typing.Annotated[numpy.typing.ArrayLike, numpy.float32],
        grid_from_sensor: typing.Annotated[numpy.typing.ArrayLike, numpy.float64],
        min_obstacle_height: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        max_obstacle_height: typing.SupportsFloat | typing.SupportsIndex = 2.0,
        merge_cells: bool = False,
    ) -> IntegrationStats:
        """
        Integrates an (N, 3) point cloud in the sensor frame placed by the 4 x 4 transform grid_from_sensor; points outside the height band (grid frame z, m) are skipped; with merge_cells one beam per grid cell (the first point in it).
        """
    def integrate_moving(
        self,
        grid: LogOddsGrid,
        ranges: typing.Annotated[numpy.typing.ArrayLike, numpy.float32],
        angle_min: typing.SupportsFloat | typing.SupportsIndex,
        angle_increment: typing.SupportsFloat | typing.SupportsIndex,
        range_min: typing.SupportsFloat | typing.SupportsIndex,
        range_max: typing.SupportsFloat | typing.SupportsIndex,
        first_beam_pose: tuple[
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
        ],
        last_beam_pose: tuple[
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
            typing.SupportsFloat | typing.SupportsIndex,
        ],
    ) -> IntegrationStats:
        """
        Like integrate(), for a scan swept while the sensor moved: each beam is cast from the pose interpolated between the first and the last beam's pose (per-beam correction).
        """
    @property
    def config(self) -> ScanIntegratorConfig: ...

class StaticMapConfig:
    """
    How an OccupancyGrid becomes costs (map_server's thresholds, track_unknown_space, trinary_costmap).
    """

    track_unknown_space: bool
    trinary_costmap: bool
    use_maximum: bool
    def __init__(self) -> None: ...
    @property
    def lethal_cost_threshold(self) -> int:
        """
        occupancy value 0..100 (clamped) from which a cell is lethal
        """
    @lethal_cost_threshold.setter
    def lethal_cost_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_cells(self) -> int:
        """
        largest map accepted, cells
        """
    @max_cells.setter
    def max_cells(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def unknown_cost_value(self) -> int:
        """
        occupancy value meaning unknown, compared as a byte (-1 = 255)
        """
    @unknown_cost_value.setter
    def unknown_cost_value(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...

class StaticMap:
    """
    A static map (nav_msgs/OccupancyGrid values) as costmap costs, with costmap_2d StaticLayer's translation.
    """
    def __init__(self, config: StaticMapConfig = ...) -> None: ...
    def apply_update(
        self,
        x: typing.SupportsInt | typing.SupportsIndex,
        y: typing.SupportsInt | typing.SupportsIndex,
        data: typing.Annotated[numpy.typing.ArrayLike, numpy.int8],
    ) -> None:
        """
        map_msgs/OccupancyGridUpdate: rewrites [x, x + w) x [y, y + h); ValueError (nothing written) if the window is not inside the map.
        """
    def costs(self) -> numpy.typing.NDArray[numpy.uint8]:
        """
        [y, x] uint8 costs.
        """
    def set_map(
        self,
        data: typing.Annotated[numpy.typing.ArrayLike, numpy.int8],
        resolution: typing.SupportsFloat | typing.SupportsIndex,
        origin_x: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        origin_y: typing.SupportsFloat | typing.SupportsIndex = 0.0,
    ) -> None:
        """
        Replaces the map ([y, x] int8 occupancy); ValueError (map kept) if it is refused.
        """
    @property
    def geometry(self) -> GridGeometry: ...
    @property
    def has_map(self) -> bool: ...
    @property
    def last_change(self) -> tuple[int, int, int, int]:
        """
        (min_x, min_y, max_x, max_y) cells, inclusive; min > max if nothing changed
        """

class InflationConfig:
    """
    Inflation radius and inscribed radius (m) and cost_scaling_factor (1/m), as costmap_2d's InflationLayer.
    """

    MAX_RADIUS_CELLS: typing.ClassVar[int] = 2000
    inflate_unknown: bool
    def __init__(self) -> None: ...
    @typing.overload
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @typing.overload
    def validate(self, resolution_m: typing.SupportsFloat | typing.SupportsIndex) -> str:
        """
        Also checks the radius in cells at this resolution.
        """
    @property
    def cost_scaling_factor(self) -> float:
        """
        1/m
        """
    @cost_scaling_factor.setter
    def cost_scaling_factor(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def inflation_radius(self) -> float:
        """
        m
        """
    @inflation_radius.setter
    def inflation_radius(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def inscribed_radius(self) -> float:
        """
        m
        """
    @inscribed_radius.setter
    def inscribed_radius(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class PredictionConfig:
    """
    How tracks are predicted into the costmap: horizon and step (s), uncertainty growth, footprint margin (m).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def max_object_size_m(self) -> float:
        """
        m
        """
    @max_object_size_m.setter
    def max_object_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_speed_mps(self) -> float:
        """
        m/s
        """
    @max_speed_mps.setter
    def max_speed_mps(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_uncertainty_m(self) -> float:
        """
        m
        """
    @max_uncertainty_m.setter
    def max_uncertainty_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_object_size_m(self) -> float:
        """
        m
        """
    @min_object_size_m.setter
    def min_object_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prediction_horizon_s(self) -> float:
        """
        s
        """
    @prediction_horizon_s.setter
    def prediction_horizon_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def uncertainty_sigmas(self) -> float: ...
    @uncertainty_sigmas.setter
    def uncertainty_sigmas(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class PlanarTrack:
    """
    One track in the costmap's frame.
    """
    def __init__(
        self,
        position: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"],
        velocity: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"],
        position_covariance: typing.Annotated[
            numpy.typing.ArrayLike, numpy.float64, "[2, 2]"
        ] = ...,
        velocity_covariance: typing.Annotated[
            numpy.typing.ArrayLike, numpy.float64, "[2, 2]"
        ] = ...,
        size_x: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        size_y: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        box_yaw: typing.SupportsFloat | typing.SupportsIndex = 0.0,
    ) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def box_yaw(self) -> float:
        """
        rad
        """
    @box_yaw.setter
    def box_yaw(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def position(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        m
        """
    @position.setter
    def position(
        self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]
    ) -> None: ...
    @property
    def position_covariance(
        self,
    ) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        """
        m^2
        """
    @position_covariance.setter
    def position_covariance(
        self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 2]"]
    ) -> None: ...
    @property
    def size_x(self) -> float:
        """
        m
        """
    @size_x.setter
    def size_x(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def size_y(self) -> float:
        """
        m
        """
    @size_y.setter
    def size_y(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def velocity(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        m/s
        """
    @velocity.setter
    def velocity(
        self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 1]"]
    ) -> None: ...
    @property
    def velocity_covariance(
        self,
    ) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 2]"]:
        """
        m^2/s^2
        """
    @velocity_covariance.setter
    def velocity_covariance(
        self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 2]"]
    ) -> None: ...

class TrackState:
    """
    Members:

      TENTATIVE

      CONFIRMED

      COASTING
    """

    COASTING: typing.ClassVar[TrackState]
    CONFIRMED: typing.ClassVar[TrackState]
    TENTATIVE: typing.ClassVar[TrackState]
    __members__: typing.ClassVar[dict[str, TrackState]]
    @typing.overload
    def __eq__(self, other: TrackState) -> bool: ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool: ...
    def __getstate__(self) -> int: ...
    def __hash__(self) -> int: ...
    def __index__(self) -> int: ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    def __int__(self) -> int: ...
    @typing.overload
    def __ne__(self, other: TrackState) -> bool: ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool: ...
    def __repr__(self) -> str: ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    def __str__(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def value(self) -> int: ...

class TrackerConfig:
    """
    Tracker parameters; metric defaults on construction, image defaults from TrackerConfig.defaults_for(Mode.IMAGE).
    """
    class Mode:
        """
        Members:

          METRIC

          IMAGE
        """

        IMAGE: typing.ClassVar[TrackerConfig.Mode]
        METRIC: typing.ClassVar[TrackerConfig.Mode]
        __members__: typing.ClassVar[dict[str, TrackerConfig.Mode]]
        @typing.overload
        def __eq__(self, other: TrackerConfig.Mode) -> bool: ...
        @typing.overload
        def __eq__(self, other: typing.Any) -> bool: ...
        def __getstate__(self) -> int: ...
        def __hash__(self) -> int: ...
        def __index__(self) -> int: ...
        def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None: ...
        def __int__(self) -> int: ...
        @typing.overload
        def __ne__(self, other: TrackerConfig.Mode) -> bool: ...
        @typing.overload
        def __ne__(self, other: typing.Any) -> bool: ...
        def __repr__(self) -> str: ...
        def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None: ...
        def __str__(self) -> str: ...
        @property
        def name(self) -> str: ...
        @property
        def value(self) -> int: ...

    MAX_BOX_COORDINATE_PX: typing.ClassVar[float] = 1000000.0
    MAX_POSITION_M: typing.ClassVar[float] = 100000000.0
    class_aware: bool
    mode: TrackerConfig.Mode
    second_pass: bool
    @staticmethod
    def defaults_for(mode: TrackerConfig.Mode) -> TrackerConfig:
        """
        The mode's documented defaults. TrackerConfig() is the metric ones; setting mode on it keeps every other field as it is.
        """
    @staticmethod
    def mode_specific_defaults(mode: TrackerConfig.Mode) -> list[tuple[str, float]]:
        """
        [(name, value)] of the fields whose default in this mode differs from the metric one.
        """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def accel_psd(self) -> float: ...
    @accel_psd.setter
    def accel_psd(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def duplicate_confidence(self) -> float: ...
    @duplicate_confidence.setter
    def duplicate_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def gate_confidence(self) -> float: ...
    @gate_confidence.setter
    def gate_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def high_score(self) -> float: ...
    @high_score.setter
    def high_score(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def initial_velocity_std(self) -> float: ...
    @initial_velocity_std.setter
    def initial_velocity_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def low_score(self) -> float: ...
    @low_score.setter
    def low_score(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_age_s(self) -> float: ...
    @max_age_s.setter
    def max_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def measurement_std(self) -> float: ...
    @measurement_std.setter
    def measurement_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_hits(self) -> int: ...
    @min_hits.setter
    def min_hits(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def min_iou(self) -> float: ...
    @min_iou.setter
    def min_iou(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def reid_confidence(self) -> float: ...
    @reid_confidence.setter
    def reid_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class TrackerStats:
    """
    What one tracker step did: detections by kind, matches per pass, births, deaths, duplicates, re-identifications.
    """
    @property
    def births(self) -> int: ...
    @property
    def confirmed(self) -> int: ...
    @property
    def deaths(self) -> int: ...
    @property
    def detections(self) -> int: ...
    @property
    def detections_ignored_low_score(self) -> int: ...
    @property
    def detections_rejected_invalid(self) -> int: ...
    @property
    def detections_rejected_out_of_range(self) -> int: ...
    @property
    def duplicates_removed(self) -> int: ...
    @property
    def id_switches(self) -> int: ...
    @property
    def matched_first_pass(self) -> int: ...
    @property
    def matched_second_pass(self) -> int: ...
    @property
    def reidentified(self) -> int: ...
    @property
    def tracks(self) -> int: ...
    @property
    def unmatched_outside_gate(self) -> int: ...

class Tracker:
    """
    SORT-style multi-object tracker (see core/tracking/tracker.h).
    """
    def __init__(self, config: TrackerConfig = ...) -> None: ...
    def last_assignment(self) -> list[int]:
        """
        Per detection of the last step: the id of the track that took it, or 0.
        """
    def reset(self) -> None:
        """
        Forgets every track (ids keep counting up).
        """
    def step(
        self,
        stamp: typing.SupportsFloat | typing.SupportsIndex,
        positions: typing.Annotated[numpy.typing.ArrayLike, numpy.float64],
        scores: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None,
        class_ids: typing.Annotated[numpy.typing.ArrayLike, numpy.int32] | None = None,
        covariances: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None,
        truth_ids: typing.Annotated[numpy.typing.ArrayLike, numpy.int32] | None = None,
        sizes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None,
    ) -> TrackerStats:
        """
        One frame: positions (N, 2) in metres (metric mode) or boxes (N, 4) in pixels (image mode); sizes (N, 2) in metres (metric mode only: tracks()['size']). Returns TrackerStats.
        """
    def tracks(self, include_tentative: bool = True) -> dict:
        """
        Live tracks as a dict of numpy arrays (id, state, hits, truth_id, position, velocity, position_cov, velocity_cov, size); state: 0 tentative, 1 confirmed, 2 coasting. include_tentative=False leaves out the tracks not yet confirmed.
        """

class SeamLimits:
    """
    The seam health's warning limits (handoff keys).
    """
    def __init__(self) -> None: ...
    @property
    def max_map_odom_age_s(self) -> float:
        """
        s
        """
    @max_map_odom_age_s.setter
    def max_map_odom_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_smear_m(self) -> float:
        """
        m
        """
    @max_smear_m.setter
    def max_smear_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_transform_age_s(self) -> float:
        """
        s
        """
    @max_transform_age_s.setter
    def max_transform_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def reference_range_m(self) -> float:
        """
        m
        """
    @reference_range_m.setter
    def reference_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class CorrectionMonitorConfig:
    """
    Limits of the map <- odom correction monitor (metres, seconds).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def max_correction_m(self) -> float:
        """
        m
        """
    @max_correction_m.setter
    def max_correction_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_travel_m(self) -> float:
        """
        m
        """
    @min_travel_m.setter
    def min_travel_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def ramp_m(self) -> float:
        """
        m
        """
    @ramp_m.setter
    def ramp_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def reset_drop_m(self) -> float:
        """
        m
        """
    @reset_drop_m.setter
    def reset_drop_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def window_s(self) -> float:
        """
        s
        """
    @window_s.setter
    def window_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def zero_epsilon_m(self) -> float:
        """
        m
        """
    @zero_epsilon_m.setter
    def zero_epsilon_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class CorrectionMonitor:
    """
    Watches |map <- odom| over time.
    """
    def __init__(self, config: CorrectionMonitorConfig = ...) -> None: ...
    def add(
        self,
        time_s: typing.SupportsFloat | typing.SupportsIndex,
        correction_m: typing.SupportsFloat | typing.SupportsIndex,
        travelled_m: typing.SupportsFloat | typing.SupportsIndex,
    ) -> None:
        """
        One sample: time (s), the correction's translation magnitude (m), the distance travelled so far (m).
        """
    def add_many(
        self,
        time_s: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"],
        correction_m: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"],
        travelled_m: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"],
    ) -> None:
        """
        Samples from three equally long arrays: time_s, correction_m, travelled_m.
        """
    def findings(self) -> list[str]:
        """
        What is wrong, one line per finding (empty if healthy).
        """
    def never_resets(self) -> bool:
        """
        Whether the correction grew by ramp_m over the window without a reset.
        """
    def stuck_at_zero(self) -> bool:
        """
        Whether the correction stayed ~0 over the window while the robot travelled min_travel_m.
        """
    def too_large(self) -> bool:
        """
        Whether the latest correction exceeds max_correction_m.
        """
    @property
    def resets(self) -> int: ...

class VoxelMapConfig:
    """
    3-D voxel obstacle map settings (costmap_2d VoxelLayer's meaning).
    """

    log_odds: LogOddsConfig
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if valid, else the reason.
        """
    @property
    def decay_time_s(self) -> float:
        """
        0 = no decay
        """
    @decay_time_s.setter
    def decay_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def mark_threshold(self) -> int:
        """
        a column with more occupied band voxels than this is lethal
        """
    @mark_threshold.setter
    def mark_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_memory_mib(self) -> float: ...
    @max_memory_mib.setter
    def max_memory_mib(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_obstacle_height_m(self) -> float: ...
    @max_obstacle_height_m.setter
    def max_obstacle_height_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_obstacle_height_m(self) -> float: ...
    @min_obstacle_height_m.setter
    def min_obstacle_height_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def origin_z_m(self) -> float:
        """
        bottom of voxel layer 0 (m)
        """
    @origin_z_m.setter
    def origin_z_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def resolution_m(self) -> float:
        """
        voxel edge in x, y (m)
        """
    @resolution_m.setter
    def resolution_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def unknown_threshold(self) -> int:
        """
        a column with at most this many unknown band voxels is known
        """
    @unknown_threshold.setter
    def unknown_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def z_resolution_m(self) -> float:
        """
        voxel height (m)
        """
    @z_resolution_m.setter
    def z_resolution_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def z_voxels(self) -> int:
        """
        voxels per column
        """
    @z_voxels.setter
    def z_voxels(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...

class VoxelRayConfig:
    """
    How far a source's rays mark and clear.
    """

    clearing: bool
    marking: bool
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if valid, else the reason.
        """
    @property
    def no_return_range_m(self) -> float: ...
    @no_return_range_m.setter
    def no_return_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def obstacle_max_range_m(self) -> float: ...
    @obstacle_max_range_m.setter
    def obstacle_max_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def one_ray_per_end_voxel(self) -> bool:
        """
        cast only the first ray of a frame ending in each voxel
        """
    @one_ray_per_end_voxel.setter
    def one_ray_per_end_voxel(self, arg0: bool) -> None: ...
    @property
    def raytrace_max_range_m(self) -> float: ...
    @raytrace_max_range_m.setter
    def raytrace_max_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class VoxelMap:
    """
    Sparse 3-D log-odds voxels over a rolling window.
    """
    def __init__(
        self,
        config: VoxelMapConfig,
        anchor_x_m: typing.SupportsFloat | typing.SupportsIndex,
        anchor_y_m: typing.SupportsFloat | typing.SupportsIndex,
        nx: typing.SupportsInt | typing.SupportsIndex,
        ny: typing.SupportsInt | typing.SupportsIndex,
    ) -> None:
        """
        Raises ValueError for an invalid config, anchor or window size.
        """
    def clear(self) -> None:
        """
        Forgets everything (all voxels unknown).
        """
    def column(
        self,
        x: typing.SupportsInt | typing.SupportsIndex,
        y: typing.SupportsInt | typing.SupportsIndex,
        now_s: typing.SupportsFloat | typing.SupportsIndex,
    ) -> tuple[int, int, int]:
        """
        (occupied, unknown, cost) of a column within the height band.
        """
    def integrate(
        self,
        origin: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
        hits: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"],
        no_returns: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"],
        stamp_s: typing.SupportsFloat | typing.SupportsIndex,
        rays: VoxelRayConfig,
    ) -> dict:
        """
        One frame: hits (N x 3, world, m) mark and clear; no_returns (M x 3) give directions that clear no_return_range_m. Returns the counts.
        """
    def integrate_depth(
        self,
        depth: typing.Annotated[numpy.typing.ArrayLike, numpy.float32],
        camera: PinholeCamera,
        T_world_camera: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[4, 4]"],
        stamp_s: typing.SupportsFloat | typing.SupportsIndex,
        rays: VoxelRayConfig,
        zero_is_no_return: bool = False,
        stride: typing.SupportsInt | typing.SupportsIndex = 1,
    ) -> dict:
        """
        A depth image (metres, REP 118: +Inf = no return) as one frame.
        """
    def log_odds(
        self,
        x: typing.SupportsInt | typing.SupportsIndex,
        y: typing.SupportsInt | typing.SupportsIndex,
        z: typing.SupportsInt | typing.SupportsIndex,
        now_s: typing.SupportsFloat | typing.SupportsIndex,
    ) -> float:
        """
        Log-odds of voxel (x, y, z) at time now_s (s; after decay).
        """
    def occupied_centres(
        self, now_s: typing.SupportsFloat | typing.SupportsIndex
    ) -> numpy.typing.NDArray[numpy.float32]:
        """
        Centres (N x 3, m) of the occupied voxels.
        """
    def project(
        self, now_s: typing.SupportsFloat | typing.SupportsIndex
    ) -> numpy.typing.NDArray[numpy.uint8]:
        """
        Column costs (ny, nx): 254 lethal, 0 free, 255 unknown.
        """
    def prune(self, now_s: typing.SupportsFloat | typing.SupportsIndex) -> int:
        """
        Frees the blocks in which no voxel is known any more at now_s (decay); returns the blocks freed.
        """
    def set_window(
        self,
        x0: typing.SupportsInt | typing.SupportsIndex,
        y0: typing.SupportsInt | typing.SupportsIndex,
        nx: typing.SupportsInt | typing.SupportsIndex,
        ny: typing.SupportsInt | typing.SupportsIndex,
    ) -> None:
        """
        Moves / resizes the window to nx x ny columns from column (x0, y0) (voxel indices); voxels inside both windows are kept, the others forgotten.
        """
    def state(
        self,
        x: typing.SupportsInt | typing.SupportsIndex,
        y: typing.SupportsInt | typing.SupportsIndex,
        z: typing.SupportsInt | typing.SupportsIndex,
        now_s: typing.SupportsFloat | typing.SupportsIndex,
    ) -> int:
        """
        -1 unknown, 0 free, 1 occupied.
        """
    @property
    def band(self) -> tuple[int, int]: ...
    @property
    def blocks(self) -> int: ...
    @property
    def config(self) -> VoxelMapConfig: ...
    @property
    def max_blocks(self) -> int: ...
    @property
    def memory_bytes(self) -> int: ...
    @property
    def shape(self) -> tuple[int, int, int]: ...
    @property
    def window_offset(self) -> tuple[int, int]: ...
    @property
    def window_origin(self) -> tuple[float, float]: ...

def apply(
    arg0: Pose2D, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]
) -> numpy.typing.NDArray[numpy.float64]:
    """
    R p + t for each row of an (N, 2) array.
    """

def bresenham_line(
    arg0: typing.SupportsInt | typing.SupportsIndex,
    arg1: typing.SupportsInt | typing.SupportsIndex,
    arg2: typing.SupportsInt | typing.SupportsIndex,
    arg3: typing.SupportsInt | typing.SupportsIndex,
) -> numpy.typing.NDArray[numpy.int32]:
    """
    Integer Bresenham cells from (x0, y0) to (x1, y1), both included; (N, 2) int array.
    """

def chi_square_quantile(
    dof: typing.SupportsInt | typing.SupportsIndex,
    confidence: typing.SupportsFloat | typing.SupportsIndex,
) -> float:
    """
    Squared-Mahalanobis gate: chi-square quantile (2, 0.99) -> 9.21.
    """

def compose(arg0: Pose2D, arg1: Pose2D) -> Pose2D:
    """
    a ∘ b (parent<-mid ∘ mid<-child = parent<-child)
    """

def expected_smear(
    range_m: typing.SupportsFloat | typing.SupportsIndex,
    yaw_rate_rps: typing.SupportsFloat | typing.SupportsIndex,
    age_s: typing.SupportsFloat | typing.SupportsIndex,
) -> float:
    """
    range * tan(|yaw rate| * age): sideways throw of a late transform, m.
    """

def footprint_cells(
    points: collections.abc.Sequence[
        tuple[
            typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex
        ]
    ],
    pose: tuple[
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
    ],
    geometry: GridGeometry,
) -> numpy.typing.NDArray[numpy.bool]:
    """
    [y, x] bool mask of the cells whose centre lies inside the footprint placed at pose = (x, y, yaw): the cells the obstacle layer clears under the robot.
    """

def footprint_radii(
    points: collections.abc.Sequence[
        tuple[
            typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex
        ]
    ],
) -> tuple[float, float]:
    """
    (inscribed, circumscribed) radius of a footprint polygon, m.
    """

def inflate(
    costs: typing.Annotated[numpy.typing.ArrayLike, numpy.uint8],
    resolution: typing.SupportsFloat | typing.SupportsIndex,
    config: InflationConfig,
) -> numpy.typing.NDArray[numpy.uint8]:
    """
    Inflates a whole [y, x] uint8 cost grid (254 = lethal) and returns the merged grid.
    """

def inflation_cost(
    distance_m: typing.SupportsFloat | typing.SupportsIndex, config: InflationConfig
) -> int:
    """
    costmap_2d's cost for a cell at distance_m from the nearest lethal cell.
    """

def interpolate(
    a: Pose2D,
    t_a: typing.SupportsFloat | typing.SupportsIndex,
    b: Pose2D,
    t_b: typing.SupportsFloat | typing.SupportsIndex,
    t: typing.SupportsFloat | typing.SupportsIndex,
) -> Pose2D:
    """
    Linear in translation, shortest arc in yaw.
    """

def inverse(arg0: Pose2D) -> Pose2D:
    """
    The inverse pose: child <- parent from parent <- child.
    """

def iou(
    a: tuple[
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
    ],
    b: tuple[
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
        typing.SupportsFloat | typing.SupportsIndex,
    ],
) -> float:
    """
    IoU of two boxes (x_min, y_min, x_max, y_max).
    """

def log_odds_of(arg0: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    log(p / (1 - p))
    """

def mask_iou(
    a: typing.Annotated[numpy.typing.ArrayLike, numpy.uint8],
    b: typing.Annotated[numpy.typing.ArrayLike, numpy.uint8],
) -> float:
    """
    IoU of two binary masks (non-zero = foreground).
    """

def nms(
    boxes: typing.Annotated[numpy.typing.ArrayLike, numpy.float64],
    scores: typing.Annotated[numpy.typing.ArrayLike, numpy.float64],
    iou_threshold: typing.SupportsFloat | typing.SupportsIndex = 0.5,
    class_ids: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] | None = None,
) -> numpy.typing.NDArray[numpy.int64]:
    """
    Greedy NMS; returns the kept indices, best first. With class_ids, per class.
    """

def normalize_angle(arg0: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    The angle (rad) wrapped into [-pi, pi).
    """

def occupancy_table() -> numpy.typing.NDArray[numpy.int8]:
    """
    cost (0..255) -> nav_msgs/OccupancyGrid value, costmap_2d's translation.
    """

def predicted_cells(
    track: PlanarTrack,
    age_s: typing.SupportsFloat | typing.SupportsIndex,
    config: PredictionConfig,
    geometry: GridGeometry,
) -> numpy.typing.NDArray[numpy.int32]:
    """
    Cells (N x 2 [x, y]) the track covers from its stamp over age_s + prediction_horizon_s. Raises ValueError if the track, age_s or the config is invalid.
    """

def probability_of(arg0: typing.SupportsFloat | typing.SupportsIndex) -> float:
    """
    1 - 1 / (1 + exp(l))
    """

def ray_cells(
    geometry: GridGeometry,
    x0: typing.SupportsFloat | typing.SupportsIndex,
    y0: typing.SupportsFloat | typing.SupportsIndex,
    x1: typing.SupportsFloat | typing.SupportsIndex,
    y1: typing.SupportsFloat | typing.SupportsIndex,
    include_end: bool = True,
) -> numpy.typing.NDArray[numpy.int32]:
    """
    Every cell the world segment crosses (Amanatides-Woo), clipped to the grid, in order.
    """

def recent_cells(
    track: PlanarTrack,
    lookback_s: typing.SupportsFloat | typing.SupportsIndex,
    age_s: typing.SupportsFloat | typing.SupportsIndex,
    margin_m: typing.SupportsFloat | typing.SupportsIndex,
    max_object_size_m: typing.SupportsFloat | typing.SupportsIndex,
    geometry: GridGeometry,
) -> numpy.typing.NDArray[numpy.int32]:
    """
    Cells (N x 2 [x, y]) under the track's box grown by margin_m, swept from lookback_s before its stamp to age_s after it (what clear_tracked_objects clears).
    """

def shortest_angular_distance(
    arg0: typing.SupportsFloat | typing.SupportsIndex,
    arg1: typing.SupportsFloat | typing.SupportsIndex,
) -> float:
    """
    Signed shortest rotation (rad) from angle `from` to angle `to`.
    """

def slice_distance(
    slice: typing.Annotated[numpy.typing.ArrayLike, numpy.int8],
    resolution: typing.SupportsFloat | typing.SupportsIndex,
    max_distance_m: typing.SupportsFloat | typing.SupportsIndex = 2.0,
) -> numpy.typing.NDArray[numpy.float32]:
    """
    Euclidean distance (m, float32 [y, x]) from each cell of a slice ([y, x]: > 0 occupied, 0 free, < 0 unknown; Tsdf.slice's output or an OccupancyGrid's data) to the nearest occupied cell, capped at max_distance_m; NaN on unknown cells.
    """

def solve_assignment(
    cost: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"],
) -> list[int]:
    """
    Min-cost assignment of rows to columns; inf = forbidden. Returns the column per row or -1.
    """

def static_map_values(
    occupancy: typing.Annotated[numpy.typing.ArrayLike, numpy.int8], config: StaticMapConfig = ...
) -> numpy.typing.NDArray[numpy.uint8]:
    """
    nav_msgs/OccupancyGrid values (int8, any shape) -> costs, costmap_2d's StaticLayer mapping.
    """

def swept_polygon(
    track: PlanarTrack,
    duration_s: typing.SupportsFloat | typing.SupportsIndex,
    config: PredictionConfig,
) -> numpy.typing.NDArray[numpy.float64]:
    """
    Convex polygon (N x 2, counter-clockwise) the box sweeps over duration_s.
    """

def uncertainty_radius(
    track: PlanarTrack, dt_s: typing.SupportsFloat | typing.SupportsIndex, config: PredictionConfig
) -> float:
    """
    k sigma of the predicted position dt_s after the stamp, m (capped).
    """

def voxel_ray(
    box: typing.Annotated[numpy.typing.ArrayLike, numpy.int32, "[3, 1]"],
    p0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
    p1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"],
    include_end: bool = True,
) -> numpy.typing.NDArray[numpy.int32]:
    """
    The voxels (N x 3) of the segment p0-p1 (voxel units) in the box [0, nx) x [0, ny) x [0, nz), in order, each once; empty when it misses the box or is not finite.
    """

FREE_SPACE: int = 0
INSCRIBED_INFLATED_OBSTACLE: int = 253
LETHAL_OBSTACLE: int = 254
NO_INFORMATION: int = 255
pybind11_version: tuple = (3, 1)
