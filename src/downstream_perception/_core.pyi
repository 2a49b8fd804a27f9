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
    "TsdfEdgeGuardRule",
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
    def origin_x(self) -> float:
        """
        x of the lower-left corner, m
        """
    @property
    def origin_y(self) -> float:
        """
        y of the lower-left corner, m
        """
    @property
    def resolution(self) -> float:
        """
        cell edge, m
        """
    @property
    def size_x(self) -> int:
        """
        cells along x
        """
    @property
    def size_y(self) -> int:
        """
        cells along y
        """

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
    def x(self) -> float:
        """
        m
        """
    @x.setter
    def x(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def y(self) -> float:
        """
        m
        """
    @y.setter
    def y(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def yaw(self) -> float:
        """
        rad, counter-clockwise from x
        """
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
    def depth_stride_px(self) -> int:
        """
        depth images: every n-th pixel in each direction is a ray
        """
    @depth_stride_px.setter
    def depth_stride_px(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_distance_m(self) -> float:
        """
        Memory bounds, the OctoMap's counterparts of the TSDF's (applied by maintain()): leaves farther than this from the sensor are deleted (0 = never; the TSDF node passes its max_block_distance_m); rays are also cut at this range (what lies beyond would go at the next maintenance anyway).
        """
    @max_distance_m.setter
    def max_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_memory_bytes(self) -> int:
        """
        Cap on memoryBytes() (octomap's count: nodes and child arrays; the heap adds the allocator's overhead, about a third more). At the cap maintain() deletes the leaves farthest from the sensor until the tree is below 90 % of it (0 = no cap).
        """
    @max_memory_bytes.setter
    def max_memory_bytes(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_range_m(self) -> float:
        """
        rays are cut at this range, m
        """
    @max_range_m.setter
    def max_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prob_hit(self) -> float:
        """
        log-odds +0.847 per hit
        """
    @prob_hit.setter
    def prob_hit(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prob_miss(self) -> float:
        """
        log-odds -0.405 per pass
        """
    @prob_miss.setter
    def prob_miss(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def resolution_m(self) -> float:
        """
        leaf size, m
        """
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
    def cx(self) -> float:
        """
        principal point x, px (pixel centres at integers)
        """
    @property
    def cy(self) -> float:
        """
        principal point y, px
        """
    @property
    def fx(self) -> float:
        """
        focal length along x, px
        """
    @property
    def fy(self) -> float:
        """
        focal length along y, px
        """
    @property
    def height(self) -> int:
        """
        image height, px
        """
    @property
    def width(self) -> int:
        """
        image width, px
        """

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
    def leaf_count(self) -> int:
        """
        leaves in the tree
        """
    @property
    def memory_bytes(self) -> int:
        """
        bytes (octomap's count for the OctoMap; the blocks' chunks for the TSDF)
        """
    @property
    def node_count(self) -> int:
        """
        nodes in the tree
        """

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

class TsdfEdgeGuardRule:
    """
    Members:

      RIM_DISTANCE

      FIXED_RADIUS
    """

    FIXED_RADIUS: typing.ClassVar[TsdfEdgeGuardRule]
    RIM_DISTANCE: typing.ClassVar[TsdfEdgeGuardRule]
    __members__: typing.ClassVar[dict[str, TsdfEdgeGuardRule]]
    @typing.overload
    def __eq__(self, other: TsdfEdgeGuardRule) -> bool: ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool: ...
    def __getstate__(self) -> int: ...
    def __hash__(self) -> int: ...
    def __index__(self) -> int: ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    def __int__(self) -> int: ...
    @typing.overload
    def __ne__(self, other: TsdfEdgeGuardRule) -> bool: ...
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
    def __init__(self) -> None: ...
    def confirm_depth(self) -> float:
        """
        The confirm depth in effect (m along the normal): confirm_depth_voxels voxels, at most confirm_depth_max_m unless that is under 1.25 voxels.
        """
    def truncation(self) -> float:
        """
        mu in metres
        """
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def behind_surface_dropoff(self) -> bool:
        """
        Behind the surface (sdf < -voxel_size_m) the weight falls linearly to 0 at -mu, so a surface seen from one side does not write a deep negative shell that ghosts when seen from the other side (voxblox's weight drop-off). Off by default: under pose noise it loses surface.
        """
    @behind_surface_dropoff.setter
    def behind_surface_dropoff(self, arg0: bool) -> None: ...
    @property
    def behind_surface_dropoff_start_voxels(self) -> float:
        """
        With behind_surface_dropoff, the weight stays 1 up to this many voxels behind the surface, then falls linearly to 0 at -mu (1 = voxblox's ramp; >= truncation_voxels = no ramp).
        """
    @behind_surface_dropoff_start_voxels.setter
    def behind_surface_dropoff_start_voxels(
        self, arg0: typing.SupportsFloat | typing.SupportsIndex
    ) -> None: ...
    @property
    def incidence_window_radius_px(self) -> int:
        """
        Depth images: incidences (rim rule, grazing reach, confirm depth) from the plane of the (2 r + 1)^2 pixels around each pixel where they all continue one surface (then radius r / 2, then 1), robust to depth noise; 0 = the nearest neighbours only.
        """
    @incidence_window_radius_px.setter
    def incidence_window_radius_px(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def confirm_depth_voxels(self) -> float:
        """
        Depth images: a voxel only ever seen deeper than this many voxels behind a surface (along its normal) is unconfirmed: it fuses and the ESDF, slice and sample() read it, but the mesh leaves it out until a frame sees it nearer a surface or in front of one (a thin slab's unseen underside). 0 = off.
        """
    @confirm_depth_voxels.setter
    def confirm_depth_voxels(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def confirm_depth_max_m(self) -> float:
        """
        Caps the confirm depth (m along the normal; 0 = no cap), never below 1.25 voxels: a slab thinner than a few coarse voxels grows no far side.
        """
    @confirm_depth_max_m.setter
    def confirm_depth_max_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def unconfirmed_update_weight(self) -> float:
        """
        Depth images: an update deeper than the confirm depth behind its surface (it does not confirm its voxel) fuses with its weight times this, so frames that see the voxel free outweigh it (no skirt under a thin slab seen from above). In (0, 1]; 1 = equal weights.
        """
    @unconfirmed_update_weight.setter
    def unconfirmed_update_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def far_free_guess_weight(self) -> float:
        """
        Depth images: an update deeper than the confirm depth on a voxel that reads free and that some frame saw more than mu in front of its surface fuses with its weight times this, and a far-free update of an unconfirmed voxel with its weight over this: free space seen beats a guess, in either order. In (0, 1]; 1 = off.
        """
    @far_free_guess_weight.setter
    def far_free_guess_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def carve_free_space(self) -> bool:
        """
        Update the voxels along the whole ray from the sensor, not only the truncation band: an object that moved away is erased where its free space is seen again (voxblox's voxel carving). Off by default: it allocates blocks for all the free space in view, so memory and time grow with the range. Carving stays inside the camera's view frustum up to max_depth_m (PinholeCamera::validate refuses intrinsics whose frustum is absurdly wide or off-axis).
        """
    @carve_free_space.setter
    def carve_free_space(self, arg0: bool) -> None: ...
    @property
    def edge_guard_grazing_voxels(self) -> float:
        """
        FIXED_RADIUS only: a guarded pixel beside the rim (not the rim pixel itself) still updates voxels up to voxel_size_m / cos(incidence) behind its surface, at most this many voxels; 1 = a voxel at any incidence.
        """
    @edge_guard_grazing_voxels.setter
    def edge_guard_grazing_voxels(
        self, arg0: typing.SupportsFloat | typing.SupportsIndex
    ) -> None: ...
    @property
    def edge_guard_near_side_only(self) -> bool:
        """
        Edge guard: only the nearer side of a depth edge (the object's rim) is a rim (FIXED_RADIUS: guarded pixels at most mu farther than it); false: both sides.
        """
    @edge_guard_near_side_only.setter
    def edge_guard_near_side_only(self, arg0: bool) -> None: ...
    @property
    def edge_guard_rad(self) -> float:
        """
        0 disables the edge guard. FIXED_RADIUS: pixels within this angle (rad) of a depth edge are guarded; RIM_DISTANCE: pixels without an incidence estimate within it update a voxel deep. 0.0075 rad is 2 pixels at f = 262.
        """
    @edge_guard_rad.setter
    def edge_guard_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def edge_guard_rim_scale(self) -> float:
        """
        RIM_DISTANCE: scales the depth a pixel's distance from the rim allows (larger: more surface next to rims, more ghosts).
        """
    @edge_guard_rim_scale.setter
    def edge_guard_rim_scale(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def edge_guard_rule(self) -> TsdfEdgeGuardRule:
        """
        Depth images: how deep behind the surface pixels next to a depth edge (an object's rim) write inside values (rays grazing a rim would otherwise write them into the free space beyond it: ghosts). RIM_DISTANCE: from each pixel's distance to the nearest rim and its incidence angle; FIXED_RADIUS: a voxel within edge_guard_rad of a rim (the rule before issue 22).
        """
    @edge_guard_rule.setter
    def edge_guard_rule(self, arg0: TsdfEdgeGuardRule) -> None: ...
    @property
    def grazing_reach_max_voxels(self) -> float:
        """
        Cap (voxels along the ray) of the grazing reach; below truncation_voxels it acts as truncation_voxels.
        """
    @grazing_reach_max_voxels.setter
    def grazing_reach_max_voxels(
        self, arg0: typing.SupportsFloat | typing.SupportsIndex
    ) -> None: ...
    @property
    def grazing_reach_voxels(self) -> float:
        """
        Depth images: every pixel writes inside values down to this many voxels below its surface (that / cos(incidence) along the ray), beyond mu if need be, at most grazing_reach_max_voxels along the ray; 0 = off.
        """
    @grazing_reach_voxels.setter
    def grazing_reach_voxels(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def interpolate_depth(self) -> bool:
        """
        Depth images: read each voxel's depth by interpolating inverse depth between the four nearest pixels (exact on planes) instead of taking the nearest pixel; falls back to the nearest pixel across depth edges (neighbours differing by more than one voxel).
        """
    @interpolate_depth.setter
    def interpolate_depth(self, arg0: bool) -> None: ...
    @property
    def max_block_distance_m(self) -> float:
        """
        Blocks whose centre is farther than this from the last sensor origin are evicted after each integration (0 = never).
        """
    @max_block_distance_m.setter
    def max_block_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_blocks(self) -> int:
        """
        Hard cap: new blocks beyond it are not allocated. Lowering it on a live map (setConfig) evicts blocks down to the new cap at once: the least recently updated first, among equally recent ones the farthest from the last sensor origin.
        """
    @max_blocks.setter
    def max_blocks(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_depth_m(self) -> float:
        """
        farther depths are invalid (at most 1000 m)
        """
    @max_depth_m.setter
    def max_depth_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_weight(self) -> float:
        """
        Cap on the fused weight, so the map keeps following a changing scene (0 = no cap).
        """
    @max_weight.setter
    def max_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def mesh_extrapolate_voxels(self) -> float:
        """
        Marching cubes fills a missing voxel (unobserved, not unconfirmed) next to the surface by linear extrapolation along a lattice axis from the two observed voxels before it, the nearer within this many voxels of the surface (keeping its sign), so the mesh reaches a surface's edge where the voxel beyond was not written. Mesh only. 0 = off; above truncation_voxels it acts as truncation_voxels.
        """
    @mesh_extrapolate_voxels.setter
    def mesh_extrapolate_voxels(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_depth_m(self) -> float:
        """
        closer depths are invalid
        """
    @min_depth_m.setter
    def min_depth_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_weight(self) -> float:
        """
        Voxels whose weight is below this are "unobserved" for meshing and queries.
        """
    @min_weight.setter
    def min_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def no_return_carve_min_valid_fraction(self) -> float:
        """
        With carve_free_space, a +Inf pixel ("no return within range", REP 118) carves its ray up to max_depth_m only in a frame where at least this fraction of all pixels are valid depths: the returns are the evidence that the sensor works and the pose is right. In other frames its +Inf pixels are ignored like invalid ones (and counted): one frame without any return (a covered or failing sensor) would otherwise carve through every wall in view. 0 = +Inf always carves; 1 = only frames without any invalid or +Inf pixel (so +Inf never carves). Without carving, +Inf pixels only free voxels of blocks the frame's returns allocate.
        """
    @no_return_carve_min_valid_fraction.setter
    def no_return_carve_min_valid_fraction(
        self, arg0: typing.SupportsFloat | typing.SupportsIndex
    ) -> None: ...
    @property
    def truncation_voxels(self) -> float:
        """
        Truncation distance mu in voxels (mu = truncation_voxels * voxel_size_m); 3-5 is usual.
        """
    @truncation_voxels.setter
    def truncation_voxels(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def voxel_size_m(self) -> float:
        """
        voxel edge, m; fixed for the map's life
        """
    @voxel_size_m.setter
    def voxel_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def weighting(self) -> TsdfWeighting:
        """
        weight of one observation
        """
    @weighting.setter
    def weighting(self, arg0: TsdfWeighting) -> None: ...

class TsdfIntegrationStats:
    """
    What one TSDF integration did: pixels by kind, blocks touched, allocated, refused, evicted, voxels updated.
    """
    @property
    def blocks_allocated(self) -> int:
        """
        of them new this frame
        """
    @property
    def blocks_evicted(self) -> int:
        """
        farther than max_block_distance_m
        """
    @property
    def blocks_refused(self) -> int:
        """
        not allocated: max_blocks reached (>= 1 if so)
        """
    @property
    def blocks_touched(self) -> int:
        """
        blocks the frame's truncation band (or rays) reached
        """
    @property
    def pixels_invalid(self) -> int:
        """
        NaN, 0, negative or outside [min_depth_m, max_depth_m]
        """
    @property
    def pixels_no_return(self) -> int:
        """
        +Inf (REP-118: nothing within range)
        """
    @property
    def pixels_no_return_ignored(self) -> int:
        """
        +Inf pixels ignored: carving, in a frame with too few valid depths (no_return_carve_min_valid_fraction); also counted in pixels_no_return.
        """
    @property
    def pixels_valid(self) -> int:
        """
        depths (or points) used
        """
    @property
    def refused(self) -> typing.Any:
        """
        Why the whole frame was refused (its pixels counted invalid), or None.
        """
    @property
    def voxels_updated(self) -> int:
        """
        voxels fused this frame
        """

class Tsdf:
    """
    Sparse TSDF (8^3-voxel blocks) with an incremental marching-cubes mesher.
    """
    def __init__(self, config: TsdfConfig = ...) -> None: ...
    def clear(self) -> None:
        """
        Forgets every block, the mesh and the ESDF.
        """
    def esdf_band_slice(
        self,
        min_z_m: typing.SupportsFloat | typing.SupportsIndex = 0.05,
        max_z_m: typing.SupportsFloat | typing.SupportsIndex = 1.8,
        max_distance_m: typing.SupportsFloat | typing.SupportsIndex = 2.0,
        grid: GridGeometry | None = None,
        max_computed_columns: typing.SupportsInt | typing.SupportsIndex = 0,
    ) -> dict:
        """
        The height band's 2-D ESDF (what the nodelet publishes as ~slice_distance): a column is occupied when a voxel of the band (centres in [min_z_m, max_z_m], m) over it is occupied (D < 0, the ESDF's rule), free when it has only free and unknown ones. dict of grid (GridGeometry: the argument, else the cells of Tsdf.slice over the map) and distance (float32 [y, x], m): (sqrt(k) - 1/2) * voxel size to the nearest occupied column (k in squared voxels), negative on occupied columns (to the nearest free one), clamped at max_distance_m, NaN on unknown columns; columns_occupied, columns_free (over the grid), columns_computed (the grid grown by the cap, within the blocks), voxels_in_band (known band voxels over the grid), padding_voxels (columns computed beyond the grid on each side) and padding_cut. grid: a window (Tsdf.slice_window) instead of the whole map; its values equal the whole map's there unless max_computed_columns (0: no bound) narrowed the padding (padding_cut: a cell nearer the edge than the cap may then read farther). Read from the map now (no esdf_update needed). Raises ValueError on an inverted band, a cap outside [one voxel, 1e6] m or a grid off the voxel lattice.
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
    def slice_window(
        self,
        centre_x_m: typing.SupportsFloat | typing.SupportsIndex,
        centre_y_m: typing.SupportsFloat | typing.SupportsIndex,
        side_m: typing.SupportsFloat | typing.SupportsIndex = 0.0,
        max_cells: typing.SupportsInt | typing.SupportsIndex = 4000000,
    ) -> tuple[GridGeometry, bool]:
        """
        The nodelet's slice grid (~slice_window_m, ~slice_max_cells): (GridGeometry, capped). A square of round(side_m / voxel) voxel columns whose middle column (n // 2) holds the centre (m), cut to the blocks' x-y extent; side_m 0: the whole extent. Larger than max_cells: cut to the floor(sqrt(max_cells)) square around the centre, capped True. An empty (0 x 0) grid when it misses every block. For Tsdf.slice and Tsdf.esdf_band_slice(grid=...). Raises ValueError on a side outside [0, 1e5] m, max_cells outside [1, 2^28] or a centre that is not finite.
        """
    def update_mesh(self) -> int:
        """
        Re-extracts the blocks changed since the last call (every block after a change of min_weight or mesh_extrapolate_voxels); returns how many.
        """
    def write_ply(self, path: str) -> None:
        """
        Writes the welded mesh as a PLY file.
        """
    @property
    def block_count(self) -> int:
        """
        allocated 8^3-voxel blocks
        """
    @property
    def blocks_evicted_to_cap(self) -> int:
        """
        Blocks evicted because set_config lowered max_blocks below the block count (total).
        """
    @property
    def config(self) -> TsdfConfig:
        """
        the configuration in use
        """
    @property
    def esdf_block_count(self) -> int:
        """
        ESDF blocks (at most one per TSDF block)
        """
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
    def memory_bytes(self) -> int:
        """
        bytes (octomap's count for the OctoMap; the blocks' chunks for the TSDF)
        """

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
        Distances are clamped at this (m). Also the reach of a change: a voxel that changes state alters distances within this radius only.
        """
    @max_distance_m.setter
    def max_distance_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class EsdfUpdateStats:
    """
    What one ESDF update did: full or incremental, regions, voxels changed.
    """
    @property
    def blocks_read(self) -> int:
        """
        TSDF blocks re-read (integrated since the last update)
        """
    @property
    def blocks_removed(self) -> int:
        """
        blocks the TSDF no longer has
        """
    @property
    def blocks_written(self) -> int:
        """
        blocks whose distances were recomputed
        """
    @property
    def full(self) -> bool:
        """
        every block recomputed
        """
    @property
    def region_voxels(self) -> int:
        """
        voxels in those regions (seed margins included)
        """
    @property
    def regions(self) -> int:
        """
        distance-transform regions
        """
    @property
    def voxels_changed(self) -> int:
        """
        voxels whose state changed
        """

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
    def clamp_max(self) -> float:
        """
        upper log-odds clamp (keeps walls un-learnable in bounded time)
        """
    @clamp_max.setter
    def clamp_max(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def clamp_min(self) -> float:
        """
        lower log-odds clamp (keeps free cells re-learnable)
        """
    @clamp_min.setter
    def clamp_min(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def free_threshold(self) -> float:
        """
        log-odds below this -> free (p < 0.119)
        """
    @free_threshold.setter
    def free_threshold(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def occupied_threshold(self) -> float:
        """
        log-odds above this -> occupied (p > 0.881)
        """
    @occupied_threshold.setter
    def occupied_threshold(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def p_hit(self) -> float:
        """
        inverse sensor model: P(occupied) given a return in the cell
        """
    @p_hit.setter
    def p_hit(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def p_miss(self) -> float:
        """
        P(occupied) given a beam passing through the cell
        """
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
    def config(self) -> LogOddsConfig:
        """
        the configuration in use
        """
    @property
    def geometry(self) -> GridGeometry:
        """
        the grid's geometry
        """
    @property
    def hit_increment(self) -> float:
        """
        log-odds added by a return, after rounding to the quantum
        """
    @property
    def memory_bytes(self) -> int:
        """
        bytes held by the cells
        """
    @property
    def miss_increment(self) -> float:
        """
        log-odds added by a pass, after rounding to the quantum
        """

class ScanIntegratorConfig:
    """
    Ranges (m) and REP-117 options of the scan integrator (costmap_2d's obstacle-source keys).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if the configuration is valid, else the reason (what the constructors raise).
        """
    @property
    def clearing(self) -> bool:
        """
        beams clear the cells they cross
        """
    @clearing.setter
    def clearing(self, arg0: bool) -> None: ...
    @property
    def inf_is_valid(self) -> bool:
        """
        +Inf means "no return": clear, do not mark
        """
    @inf_is_valid.setter
    def inf_is_valid(self, arg0: bool) -> None: ...
    @property
    def marking(self) -> bool:
        """
        returns mark their cell
        """
    @marking.setter
    def marking(self, arg0: bool) -> None: ...
    @property
    def obstacle_max_range(self) -> float:
        """
        m: returns farther than this do not mark
        """
    @obstacle_max_range.setter
    def obstacle_max_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def obstacle_min_range(self) -> float:
        """
        m: returns nearer than this do not mark
        """
    @obstacle_min_range.setter
    def obstacle_min_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def range_max_is_no_return(self) -> bool:
        """
        treat r == range_max as +Inf
        """
    @range_max_is_no_return.setter
    def range_max_is_no_return(self, arg0: bool) -> None: ...
    @property
    def raytrace_max_range(self) -> float:
        """
        m: clearing stops this far from the sensor
        """
    @raytrace_max_range.setter
    def raytrace_max_range(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def raytrace_min_range(self) -> float:
        """
        m: clearing starts this far from the sensor
        """
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
    def beams(self) -> int:
        """
        beams offered
        """
    @property
    def beams_beyond_obstacle_range(self) -> int:
        """
        returns too far (or near) to mark
        """
    @property
    def beams_invalid(self) -> int:
        """
        NaN, -Inf, outside [range_min, range_max]
        """
    @property
    def beams_marked(self) -> int:
        """
        beams whose hit cell got (or shared) a hit update
        """
    @property
    def beams_no_return(self) -> int:
        """
        +Inf (or range_max when treated so) beams that cleared
        """
    @property
    def cells_changed(self) -> int:
        """
        cells whose state (free/occupied/unknown) changed
        """
    @property
    def cells_cleared(self) -> int:
        """
        Cells walked by clearing rays, per beam (a cell two beams cross counts twice, as in the lesson's "a 10 m beam clears ~200 cells"). Each cell still receives at most one miss update per scan, and none if it was hit in the same scan.
        """
    @property
    def cells_marked(self) -> int:
        """
        cells that received a hit update
        """
    @property
    def changed(self) -> tuple:
        """
        (x0, y0, x1, y1) cells whose state changed, or None
        """
    @property
    def points_merged(self) -> int:
        """
        cloud points sharing a merge cell with an earlier one
        """
    @property
    def points_outside_height(self) -> int:
        """
        cloud points outside [min, max]_obstacle_height
        """
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
    def config(self) -> ScanIntegratorConfig:
        """
        the configuration in use
        """
    @property
    def threads(self) -> int:
        """
        threads of the clearing walk: 1, or 2 (the default where the machine has two cores) for dense scans (200,000 ray cells or more); the grid is the same bit for bit
        """
    @threads.setter
    def threads(self, arg1: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def walk_runs(self) -> dict:
        """
        scans over seen space walked by each clearing walk, as timed and chosen by the integrator (per_ray, blocks, reverse_query, first_visit; *_shared: on two threads); the grid is the same whichever ran
        """

class StaticMapConfig:
    """
    How an OccupancyGrid becomes costs (map_server's thresholds, track_unknown_space, trinary_costmap).
    """
    def __init__(self) -> None: ...
    @property
    def lethal_cost_threshold(self) -> int:
        """
        occupancy value (0..100) from which a cell is lethal
        """
    @lethal_cost_threshold.setter
    def lethal_cost_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_cells(self) -> int:
        """
        Largest map accepted (cells); a bigger one is refused. Bounds the layer's memory (one byte per cell here, one in the master, one in each published grid).
        """
    @max_cells.setter
    def max_cells(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def track_unknown_space(self) -> bool:
        """
        costmap_2d's StaticLayer default (layer level)
        """
    @track_unknown_space.setter
    def track_unknown_space(self, arg0: bool) -> None: ...
    @property
    def trinary_costmap(self) -> bool:
        """
        false: below-lethal values scale to 0..253
        """
    @trinary_costmap.setter
    def trinary_costmap(self, arg0: bool) -> None: ...
    @property
    def unknown_cost_value(self) -> int:
        """
        occupancy value meaning unknown (compared as a byte)
        """
    @unknown_cost_value.setter
    def unknown_cost_value(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def use_maximum(self) -> bool:
        """
        combine with the master by max instead of overwriting
        """
    @use_maximum.setter
    def use_maximum(self, arg0: bool) -> None: ...

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
    def geometry(self) -> GridGeometry:
        """
        the grid's geometry
        """
    @property
    def has_map(self) -> bool:
        """
        whether a map was accepted
        """
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
        1/m: exponential decay rate beyond the inscribed radius
        """
    @cost_scaling_factor.setter
    def cost_scaling_factor(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def inflate_unknown(self) -> bool:
        """
        write inflated costs over NO_INFORMATION cells (costmap_2d)
        """
    @inflate_unknown.setter
    def inflate_unknown(self, arg0: bool) -> None: ...
    @property
    def inflation_radius(self) -> float:
        """
        m: cells farther than this from any lethal cell get 0
        """
    @inflation_radius.setter
    def inflation_radius(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def inscribed_radius(self) -> float:
        """
        m: from the footprint; cells this close get 253
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
        m: larger box sides are clamped to this (bad sizes)
        """
    @max_object_size_m.setter
    def max_object_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_speed_mps(self) -> float:
        """
        m/s: faster tracks are not swept (bad velocities)
        """
    @max_speed_mps.setter
    def max_speed_mps(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_uncertainty_m(self) -> float:
        """
        m: cap on that growth, so a track with an absurd covariance cannot blank the map.
        """
    @max_uncertainty_m.setter
    def max_uncertainty_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_object_size_m(self) -> float:
        """
        m: smaller box sides are raised to this
        """
    @min_object_size_m.setter
    def min_object_size_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def prediction_horizon_s(self) -> float:
        """
        s: how far ahead of now the object is swept
        """
    @prediction_horizon_s.setter
    def prediction_horizon_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def uncertainty_sigmas(self) -> float:
        """
        k: the shape grows by k standard deviations of the predicted position (0 = box only).
        """
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
        rad: the box's x axis in the costmap frame
        """
    @box_yaw.setter
    def box_yaw(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def position(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        m, at the measurement stamp
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
        m² (m² (m^2))
        """
    @position_covariance.setter
    def position_covariance(
        self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[2, 2]"]
    ) -> None: ...
    @property
    def size_x(self) -> float:
        """
        m, box side along the box's x axis
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
        m²/s² (m²/s² (m^2/s^2))
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
    def accel_psd(self) -> float:
        """
        Spectral density of the white acceleration noise. Metric: m^2/s^3 per axis. Image: box heights^2/s^3 (px^2/s^3 per px^2 of box height), so it scales with the apparent size.
        """
    @accel_psd.setter
    def accel_psd(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def class_aware(self) -> bool:
        """
        tracks only take detections of their class
        """
    @class_aware.setter
    def class_aware(self, arg0: bool) -> None: ...
    @property
    def confirm_at_start(self) -> bool:
        """
        Start-up confirmation (ByteTrack's frame-1 rule): in the tracker's first frame (the first step() after construction or reset()), a track born from a detection whose score is at least start_confirm_score is confirmed at once instead of waiting min_hits updates. Tracks born later, and first-frame ones below the score, follow min_hits. Only the first step() counts, even when it holds no detections.
        """
    @confirm_at_start.setter
    def confirm_at_start(self, arg0: bool) -> None: ...
    @property
    def duplicate_confidence(self) -> float:
        """
        Metric mode: a coasting track this close (chi-square gate, 2 dof, sum of both position covariances) to a track born while it coasted and updated this frame is its duplicate and is removed. 0.9 -> 4.61, about 0.3 m at 0.1 m uncertainty.
        """
    @duplicate_confidence.setter
    def duplicate_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def gate_confidence(self) -> float:
        """
        chi-square gate (metric): 2 dof, 0.99 -> 9.21, 0.999 -> 13.8
        """
    @gate_confidence.setter
    def gate_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def high_score(self) -> float:
        """
        detections at or above: first pass, may start tracks
        """
    @high_score.setter
    def high_score(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def initial_velocity_std(self) -> float:
        """
        m/s (metric) or box heights/s (image)
        """
    @initial_velocity_std.setter
    def initial_velocity_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def low_score(self) -> float:
        """
        below: ignored; in between: second pass only
        """
    @low_score.setter
    def low_score(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_age_s(self) -> float:
        """
        s a confirmed track coasts without detections (both modes)
        """
    @max_age_s.setter
    def max_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def maximize_matches(self) -> bool:
        """
        Image mode: true (member default, SORT) makes as many pairs as the gate allows, then the largest summed IoU; false (image default) the largest summed (IoU - min_iou), as ByteTrack's lapjv with a cost limit, so one good pair is not traded for two poor ones. Metric mode always maximises the pairs.
        """
    @maximize_matches.setter
    def maximize_matches(self, arg0: bool) -> None: ...
    @property
    def measurement_std(self) -> float:
        """
        Metric: m, position noise of detections without a covariance. Image: box heights (std of each of centre x, centre y, width and height in px per px of box height).
        """
    @measurement_std.setter
    def measurement_std(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_hits(self) -> int:
        """
        Updates before a track is confirmed; a tentative track that misses one is dropped. Image default 2 (see defaultsFor).
        """
    @min_hits.setter
    def min_hits(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def min_iou(self) -> float:
        """
        image mode: minimum IoU to associate
        """
    @min_iou.setter
    def min_iou(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def mode(self) -> TrackerConfig.Mode:
        """
        The member initialisers below are the metric defaults (a default-constructed config is metric, as it always was). Image mode has its own defaults: start from defaultsFor(kImage).
        """
    @mode.setter
    def mode(self, arg0: TrackerConfig.Mode) -> None: ...
    @property
    def reid_confidence(self) -> float:
        """
        Metric mode: a track confirmed this frame takes the id of a track that was already coasting at its birth when their positions agree within this chi-square gate (2 dof, sum of covariances): re-identification after an occlusion the gate could not bridge. 0.99999 -> 23.0.
        """
    @reid_confidence.setter
    def reid_confidence(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def second_pass(self) -> bool:
        """
        ByteTrack's low-score association
        """
    @second_pass.setter
    def second_pass(self, arg0: bool) -> None: ...
    @property
    def start_confirm_score(self) -> float:
        """
        Score in [0, 1] a first-frame detection needs for start-up confirmation. ByteTrack's det_thresh = track_thresh + 0.1: 0.6 with high_score 0.5. Births need high_score anyway.
        """
    @start_confirm_score.setter
    def start_confirm_score(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...

class TrackerStats:
    """
    What one tracker step did: detections by kind, matches per pass, births, deaths, duplicates, re-identifications.
    """
    @property
    def births(self) -> int:
        """
        new tentative tracks
        """
    @property
    def confirmed(self) -> int:
        """
        of them confirmed or coasting
        """
    @property
    def deaths(self) -> int:
        """
        includes duplicates removed
        """
    @property
    def detections(self) -> int:
        """
        detections given to step()
        """
    @property
    def detections_ignored_low_score(self) -> int:
        """
        scores below low_score
        """
    @property
    def detections_rejected_invalid(self) -> int:
        """
        NaN/Inf, boxes with min > max or no area, negative sizes, covariances that are not positive semi-definite
        """
    @property
    def detections_rejected_out_of_range(self) -> int:
        """
        Finite but beyond TrackerConfig::kMaxBoxCoordinatePx (image) or kMaxPositionM (metric)
        """
    @property
    def duplicates_removed(self) -> int:
        """
        coasting tracks removed as duplicates of new ones
        """
    @property
    def id_switches(self) -> int:
        """
        truth objects whose track id changed (needs truth ids)
        """
    @property
    def matched_first_pass(self) -> int:
        """
        high-score detections assigned to a track
        """
    @property
    def matched_second_pass(self) -> int:
        """
        low-score detections assigned (ByteTrack's pass)
        """
    @property
    def reidentified(self) -> int:
        """
        new tracks that took a coasting track's id
        """
    @property
    def tracks(self) -> int:
        """
        live tracks after the step (every state)
        """
    @property
    def unmatched_outside_gate(self) -> int:
        """
        high-score detections no track could take
        """

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
        s: warn when map <- odom is older
        """
    @max_map_odom_age_s.setter
    def max_map_odom_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_smear_m(self) -> float:
        """
        m: warn when the expected smear exceeds it
        """
    @max_smear_m.setter
    def max_smear_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_transform_age_s(self) -> float:
        """
        s: warn when an input's p95 transform age exceeds it
        """
    @max_transform_age_s.setter
    def max_transform_age_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def reference_range_m(self) -> float:
        """
        m: the range at which the smear is judged
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
        m: warn above (the lesson: 2 m ~ 100 m of 2 % drift)
        """
    @max_correction_m.setter
    def max_correction_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_travel_m(self) -> float:
        """
        m of robot travel within the window after which a correction stuck at zero is suspicious (the localiser may be silently rejecting fixes).
        """
    @min_travel_m.setter
    def min_travel_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def ramp_m(self) -> float:
        """
        m the correction must grow within the window without a single reset before it counts as "never resets" (loop closures not firing).
        """
    @ramp_m.setter
    def ramp_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def reset_drop_m(self) -> float:
        """
        m: a fall of the correction this large is a correction event
        """
    @reset_drop_m.setter
    def reset_drop_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def window_s(self) -> float:
        """
        s of history judged
        """
    @window_s.setter
    def window_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def zero_epsilon_m(self) -> float:
        """
        m: a correction this small counts as zero
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
    def resets(self) -> int:
        """
        corrections seen to reset (drops larger than reset_drop_m) in the window
        """

class VoxelMapConfig:
    """
    3-D voxel obstacle map settings (costmap_2d VoxelLayer's meaning).
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if valid, else the reason.
        """
    @property
    def decay_time_s(self) -> float:
        """
        Time constant of the decay toward unknown, s: evidence is multiplied by exp(-dt / tau) for the time dt since the voxel's last update. 0 = no decay (costmap_2d has none). Default 0.
        """
    @decay_time_s.setter
    def decay_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def log_odds(self) -> LogOddsConfig:
        """
        Inverse sensor model per voxel. Defaults: p_hit 0.7 (+0.847), p_miss 0.4 (-0.405), clamp [-2, 3.5] (octomap's 0.12 / 0.97), occupied above 0.5 (one hit marks, as in costmap_2d), free below -0.3 (one miss frees).
        """
    @log_odds.setter
    def log_odds(self, arg0: LogOddsConfig) -> None: ...
    @property
    def mark_threshold(self) -> int:
        """
        A column with MORE than this many occupied voxels in the height band is lethal (costmap_2d `mark_threshold`). Default 0: one occupied voxel marks.
        """
    @mark_threshold.setter
    def mark_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def max_memory_mib(self) -> float:
        """
        Memory bound for the voxel blocks, MiB. Updates that would need a block beyond it are dropped and counted. Default 64.
        """
    @max_memory_mib.setter
    def max_memory_mib(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def max_obstacle_height_m(self) -> float:
        """
        top of the band projected into the costmap, m
        """
    @max_obstacle_height_m.setter
    def max_obstacle_height_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def min_obstacle_height_m(self) -> float:
        """
        The robot's height band, m: only voxels whose centre lies in [min, max] are projected into the 2-D costmap (an overhang above the robot is kept in 3-D but ignored). Defaults 0 and 2.
        """
    @min_obstacle_height_m.setter
    def min_obstacle_height_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def origin_z_m(self) -> float:
        """
        Height of the bottom of voxel layer 0, m (costmap_2d `origin_z`). Default 0.
        """
    @origin_z_m.setter
    def origin_z_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def resolution_m(self) -> float:
        """
        Edge of a voxel in x and y, m (the layer uses the costmap's resolution). Default 0.05.
        """
    @resolution_m.setter
    def resolution_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def unknown_threshold(self) -> int:
        """
        A column with AT MOST this many unknown voxels is known; a known column that is not lethal is free, any other is unknown (costmap_2d `unknown_threshold`). Counted as costmap_2d counts: the band's unknown voxels plus 16 - band when the band has fewer than 16 voxels (costmap_2d's 16-bit column). Default 15: with 10 voxels, a column is free once one of its voxels is known, and unknown until then.
        """
    @unknown_threshold.setter
    def unknown_threshold(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...
    @property
    def z_resolution_m(self) -> float:
        """
        Height of a voxel, m (costmap_2d VoxelLayer `z_resolution`). Default 0.2.
        """
    @z_resolution_m.setter
    def z_resolution_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def z_voxels(self) -> int:
        """
        Voxels per column (costmap_2d `z_voxels`, there at most 16; here at most kMaxZVoxels). Default 10.
        """
    @z_voxels.setter
    def z_voxels(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None: ...

class VoxelRayConfig:
    """
    How far a source's rays mark and clear.
    """
    def __init__(self) -> None: ...
    def validate(self) -> str:
        """
        Empty string if valid, else the reason.
        """
    @property
    def clearing(self) -> bool:
        """
        rays clear the voxels they cross
        """
    @clearing.setter
    def clearing(self, arg0: bool) -> None: ...
    @property
    def marking(self) -> bool:
        """
        returns mark their voxel
        """
    @marking.setter
    def marking(self, arg0: bool) -> None: ...
    @property
    def no_return_range_m(self) -> float:
        """
        a no-return ray clears this far, m
        """
    @no_return_range_m.setter
    def no_return_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def obstacle_max_range_m(self) -> float:
        """
        returns farther than this do not mark (3-D distance)
        """
    @obstacle_max_range_m.setter
    def obstacle_max_range_m(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None: ...
    @property
    def one_ray_per_end_voxel(self) -> bool:
        """
        Of the rays of a frame that end in the same voxel, cast only the first (every return still marks). Each cast ray is still walked exactly; a voxel crossed only by a skipped ray (beside the cast one, near the end, where rays to one voxel diverge by less than a voxel) is not cleared in that frame. Trades that for far fewer rays: a 640x480 depth image has ~40 pixels per 5 cm voxel at 4 m. Default false (every ray exact, costmap_2d's behaviour).
        """
    @one_ray_per_end_voxel.setter
    def one_ray_per_end_voxel(self, arg0: bool) -> None: ...
    @property
    def raytrace_max_range_m(self) -> float:
        """
        rays clear at most this far, m
        """
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
    def clear_columns(
        self,
        columns: typing.Annotated[numpy.typing.ArrayLike, numpy.int64],
        stamp_s: typing.SupportsFloat | typing.SupportsIndex,
    ) -> dict:
        """
        costmap_2d's footprint clearing in 3-D: every band voxel of the given window columns (N x 2: x, y) becomes free; columns outside the window are skipped. Returns the counts.
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
        clearing_mode: str = "ray",
    ) -> dict:
        """
        A depth image (metres, REP 118: +Inf = no return) as one frame. clearing_mode 'ray': every stride-th pixel's ray clears the voxels it crosses (exact 3-D traversal); 'frustum': every voxel in view nearer than the depth of the pixel it projects to (by more than half its diagonal) gets a miss, the spatio-temporal voxel layer's way, and every stride-th pixel marks. invalid_pixels is counted in 'ray' mode only.
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
    def band(self) -> tuple[int, int]:
        """
        (first, last) voxel layers inside the height band
        """
    @property
    def blocks(self) -> int:
        """
        allocated 8^3-voxel blocks
        """
    @property
    def config(self) -> VoxelMapConfig:
        """
        the configuration in use
        """
    @property
    def max_blocks(self) -> int:
        """
        blocks allowed by max_memory_mib
        """
    @property
    def memory_bytes(self) -> int:
        """
        bytes held by blocks and the block table
        """
    @property
    def shape(self) -> tuple[int, int, int]:
        """
        (nx, ny, nz) voxels of the window
        """
    @property
    def window_offset(self) -> tuple[int, int]:
        """
        (x, y) index of the window's first column on the map's lattice
        """
    @property
    def window_origin(self) -> tuple[float, float]:
        """
        (x, y) of the window's lower-left corner, m
        """

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
    unmatched_pair_cost: typing.SupportsFloat | typing.SupportsIndex = ...,
) -> list[int]:
    """
    Min-cost assignment of rows to columns; inf = forbidden. Returns the column per row or -1. unmatched_pair_cost inf (default): as many pairs as possible, then the least total cost; finite L: the least sum of (cost - L), pairs costing L or more never taken (lap.lapjv with cost_limit L, as ByteTrack calls it).
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
