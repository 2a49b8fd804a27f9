"""What a move_base costmap pair means to costmap_2d, computed from its YAML files alone (no ROS):
the parameters loaded the way move_base's launch files load them, the plugin list costmap_2d
uses (generated from the pre-Hydro keys when `plugins` is absent), each layer's keys looked up
as costmap_2d looks them up, the footprint's inscribed radius, the inflation cost formula and the
OccupancyGrid translation; plus the test scene built from those numbers (a static map, boxes at
distances derived from obstacle_range, sensor frames and heights).

Shared by the real-config simulator (real_config_sim.py), the rostest (test_real_configs.py) and
its pytest. Everything here restates costmap_2d's documented behaviour (costmap_2d_ros.cpp
loadOldParameters / copyParentParameters, obstacle_layer.cpp onInitialize, inflation_layer.h
computeCost, footprint.cpp, costmap_2d_publisher.cpp), so a number the tests expect can be traced
to a key in the robot's YAML.
"""

from __future__ import annotations

import copy
import json
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import yaml

NO_INFORMATION, LETHAL, INSCRIBED, FREE = 255, 254, 253, 0
OBSTACLE_TYPES = ("costmap_2d::ObstacleLayer", "costmap_2d::VoxelLayer")
STATIC_TYPE = "costmap_2d::StaticLayer"
INFLATION_TYPE = "costmap_2d::InflationLayer"
OBSTACLE_TYPE, VOXEL_TYPE = OBSTACLE_TYPES
# The keys costmap_2d copies from the costmap into a layer of each type (copyParentParameters);
# loadOldParameters moves the same keys into the layers it generates.
COPIED_KEYS: dict[str, tuple[str, ...]] = {
    STATIC_TYPE: (
        "map_topic",
        "unknown_cost_value",
        "lethal_cost_threshold",
        "track_unknown_space",
    ),
    VOXEL_TYPE: (
        "origin_z",
        "z_resolution",
        "z_voxels",
        "mark_threshold",
        "unknown_threshold",
        "publish_voxel_map",
    ),
    OBSTACLE_TYPE: (
        "max_obstacle_height",
        "raytrace_range",
        "obstacle_range",
        "track_unknown_space",
    ),
    INFLATION_TYPE: ("cost_scaling_factor", "inflation_radius"),
}
# Our own spellings of the same layers count as the same kind.
OUR_TYPES = {
    "downstream_perception/LogOddsObstacleLayer": "costmap_2d::ObstacleLayer",
    "downstream_perception/StaticLayer": STATIC_TYPE,
    "downstream_perception/InflationLayer": INFLATION_TYPE,
}

Params = dict[str, Any]


def translate(cost: int) -> int:
    """costmap_2d's OccupancyGrid value for a cost (costmap_2d_publisher.cpp)."""
    if cost == FREE:
        return 0
    if cost == INSCRIBED:
        return 99
    if cost == LETHAL:
        return 100
    if cost == NO_INFORMATION:
        return -1
    return 1 + (97 * (cost - 1)) // 251


def merge(tree: Params, ns: str, values: Params) -> None:
    """roslaunch's `<rosparam command="load" ns=ns>`: dictionaries are unrolled, so every leaf
    (lists included) is set on its own and a later file overrides single keys only."""
    node = tree
    for part in [p for p in ns.strip("/").split("/") if p]:
        node = node.setdefault(part, {})
    for key, value in values.items():
        if isinstance(value, dict):
            if not isinstance(node.get(key), dict):
                node[key] = {}
            merge(node[key], "", value)
        else:
            node[key] = copy.deepcopy(value)


def load_pair_from(get: Any, ns: str = "/real_config") -> Params:
    """load_pair() with its arguments read through `get` (rospy.get_param) from `ns`."""
    return load_pair(
        get(f"{ns}/common"),
        get(f"{ns}/global"),
        get(f"{ns}/local"),
        get(f"{ns}/global_ns", ""),
        get(f"{ns}/local_ns", ""),
        get(f"{ns}/extra", ""),
        get(f"{ns}/root", ""),
        get(f"{ns}/global_more", ""),
        get(f"{ns}/local_more", ""),
        get(f"{ns}/common_more", ""),
    )


def load_pair(
    common: str,
    global_file: str,
    local_file: str,
    global_ns: str = "",
    local_ns: str = "",
    extra: str = "",
    root: str = "",
    global_more: str = "",
    local_more: str = "",
    common_more: str = "",
) -> Params:
    """The parameter tree move_base's launch files build: `root` (move_base's own file, e.g. the
    footprint) at the root, the common file into global_costmap and local_costmap, then the global
    and local files (each followed by its optional `*_more` file, e.g. a plugins list; the
    common file by `common_more`, e.g. Fetch's per-robot common file) into
    global_ns / local_ns ("" when the file starts with its own `global_costmap:` /
    `local_costmap:` key), then `extra` at the root."""
    tree: Params = {}

    def read(path: str) -> Params:
        with open(path, encoding="utf-8") as f:
            return yaml.safe_load(f) or {}

    if root:
        merge(tree, "", read(root))
    merge(tree, "global_costmap", read(common))
    merge(tree, "local_costmap", read(common))
    if common_more:
        merge(tree, "global_costmap", read(common_more))
        merge(tree, "local_costmap", read(common_more))
    merge(tree, global_ns, read(global_file))
    if global_more:
        merge(tree, global_ns, read(global_more))
    merge(tree, local_ns, read(local_file))
    if local_more:
        merge(tree, local_ns, read(local_more))
    if extra:
        merge(tree, "", read(extra))
    return tree


def search(chain: list[Params], key: str) -> Any:
    """ros::NodeHandle::searchParam: the innermost namespace of `chain` (innermost first) that
    holds `key`, else None."""
    for ns in chain:
        if isinstance(ns, dict) and key in ns:
            return ns[key]
    return None


def _move(src: Params, dst: Params, key: str, delete: bool = True) -> None:
    """costmap_2d_ros.cpp move_parameter: copy (overwriting) and by default delete the source."""
    if key in src:
        dst[key] = copy.deepcopy(src[key])
        if delete:
            del src[key]


def _move_pre_hydro(src: Params, dst: Params, keys: tuple[str, ...]) -> None:
    """loadOldParameters' moves: every key leaves the costmap, except track_unknown_space, which
    is copied (the costmap keeps its own)."""
    for key in keys:
        _move(src, dst, key, delete=key != "track_unknown_space")


def plugin_list(costmap: Params) -> list[dict[str, str]]:
    """The layers costmap_2d loads, applying its parameter moves to `costmap` in place: the
    `plugins` list (after copyParentParameters), or the pre-Hydro list loadOldParameters
    generates from static_map and map_type."""
    if "plugins" in costmap:
        plugins = [{"name": str(p["name"]), "type": str(p["type"])} for p in costmap["plugins"]]
        for p in plugins:
            if not isinstance(costmap.get(p["name"]), dict):
                # A layer named like a scalar key (Freight's `static_map` layer beside
                # `static_map: true`) reads none of it: its own keys are all defaults.
                costmap[p["name"]] = {}
            layer = costmap[p["name"]]
            kind = OUR_TYPES.get(p["type"], p["type"])
            keys = COPIED_KEYS.get(kind, ())
            for key in keys:
                _move(costmap, layer, key, delete=False)
        return plugins
    plugins = []
    if costmap.get("static_map") is True:
        plugins.append({"name": "static_layer", "type": STATIC_TYPE})
        _move_pre_hydro(costmap, costmap.setdefault("static_layer", {}), COPIED_KEYS[STATIC_TYPE])
    obstacles = costmap.setdefault("obstacle_layer", {})
    if costmap.get("map_type") == "voxel":
        plugins.append({"name": "obstacle_layer", "type": VOXEL_TYPE})
        _move_pre_hydro(costmap, obstacles, COPIED_KEYS[VOXEL_TYPE])
    else:
        plugins.append({"name": "obstacle_layer", "type": OBSTACLE_TYPE})
    _move_pre_hydro(costmap, obstacles, COPIED_KEYS[OBSTACLE_TYPE])
    for source in str(costmap.get("observation_sources", "")).split():
        _move(costmap, obstacles, source)
    _move(costmap, obstacles, "observation_sources")
    _move_pre_hydro(costmap, costmap.setdefault("inflation_layer", {}), COPIED_KEYS[INFLATION_TYPE])
    plugins.append({"name": "inflation_layer", "type": INFLATION_TYPE})
    costmap["plugins"] = plugins
    return plugins


@dataclass
class Source:
    """One observation source with costmap_2d's defaults (obstacle_layer.cpp onInitialize)."""

    name: str
    topic: str  # resolved: a relative name lives in the node's namespace, "/" here
    data_type: str
    sensor_frame: str
    obstacle_range: float
    raytrace_range: float
    min_obstacle_height: float
    max_obstacle_height: float
    marking: bool
    clearing: bool
    inf_is_valid: bool


@dataclass
class Layer:
    name: str
    type: str  # costmap_2d's type name (ours mapped to it)
    params: Params
    sources: list[Source] = field(default_factory=list)

    @property
    def kind(self) -> str:
        if self.type in OBSTACLE_TYPES:
            return "obstacle"
        return {STATIC_TYPE: "static", INFLATION_TYPE: "inflation"}.get(self.type, "other")

    def get(self, key: str, default: Any) -> Any:
        return self.params.get(key, default)

    def z_band(self) -> tuple[float, float]:
        """Heights (m, in the costmap's frame) a point can mark at: the layer's
        max_obstacle_height and, for a VoxelLayer, its voxel column."""
        top = float(self.get("max_obstacle_height", 2.0))
        bottom = -math.inf
        if self.type == "costmap_2d::VoxelLayer":
            origin_z = float(self.get("origin_z", 0.0))
            bottom = origin_z
            top = min(
                top, origin_z + float(self.get("z_resolution", 0.2)) * int(self.get("z_voxels", 10))
            )
        return bottom, top


def ros_int(value: Any) -> int:
    """roscpp reading a double into an int parameter (dynamic_reconfigure's int_t width and
    height): rounded half up."""
    d = float(value)
    return int(math.floor(d) if math.fmod(d, 1.0) < 0.5 else math.ceil(d))


def resolve_topic(topic: str) -> str:
    """A topic as costmap_2d resolves it for a node in the root namespace (ros::NodeHandle())."""
    return topic if topic.startswith("/") else "/" + topic


def parse_footprint(value: Any) -> list[tuple[float, float]] | None:
    """The footprint parameter as a list, a string "[[x, y], ...]", or None if unusable."""
    if isinstance(value, str):
        if value.strip() in ("", "[]"):
            return None
        value = json.loads(value)
    if isinstance(value, list) and len(value) >= 3:
        return [(float(p[0]), float(p[1])) for p in value]
    return None


def _segment_distance(ax: float, ay: float, bx: float, by: float) -> float:
    """Distance from (0, 0) to the segment a-b (footprint.cpp distanceToLine)."""
    dx, dy = bx - ax, by - ay
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0.0 else max(0.0, min(1.0, -(ax * dx + ay * dy) / length2))
    return math.hypot(ax + t * dx, ay + t * dy)


@dataclass
class Costmap:
    """One costmap (global_costmap or local_costmap) as costmap_2d reads it."""

    ns: str
    params: Params
    chain: list[Params]  # searchParam chain, innermost first: this costmap, then the root
    layers: list[Layer]

    @classmethod
    def from_tree(cls, tree: Params, ns: str) -> Costmap:
        tree = copy.deepcopy(tree)
        params = tree.setdefault(ns, {})
        plugins = plugin_list(params)
        layers = []
        for p in plugins:
            layer = Layer(p["name"], OUR_TYPES.get(p["type"], p["type"]), params.get(p["name"], {}))
            if layer.kind == "obstacle":
                for name in str(layer.get("observation_sources", "")).split():
                    src = layer.params.get(name, {})
                    chain = [src, layer.params, params, tree]

                    def found(key: str, default: float, chain: list[Params] = chain) -> float:
                        value = search(chain, key)
                        return default if value is None else float(value)

                    layer.sources.append(
                        Source(
                            name=name,
                            topic=resolve_topic(str(src.get("topic", name))),
                            data_type=str(src.get("data_type", "PointCloud")),
                            sensor_frame=str(src.get("sensor_frame", "")),
                            obstacle_range=found("obstacle_range", 2.5),
                            raytrace_range=found("raytrace_range", 3.0),
                            min_obstacle_height=float(src.get("min_obstacle_height", 0.0)),
                            max_obstacle_height=float(src.get("max_obstacle_height", 2.0)),
                            marking=bool(src.get("marking", True)),
                            clearing=bool(src.get("clearing", False)),
                            inf_is_valid=bool(src.get("inf_is_valid", False)),
                        )
                    )
            layers.append(layer)
        return cls(ns=ns, params=params, chain=[params, tree], layers=layers)

    def get(self, key: str, default: Any) -> Any:
        return self.params.get(key, default)

    @property
    def global_frame(self) -> str:
        return str(self.get("global_frame", "map"))

    @property
    def robot_base_frame(self) -> str:
        return str(self.get("robot_base_frame", "base_link"))

    @property
    def rolling(self) -> bool:
        return bool(self.get("rolling_window", False))

    @property
    def resolution(self) -> float:
        return float(self.get("resolution", 0.05))

    def size_cells(self) -> tuple[int, int]:
        """costmap_2d: (unsigned int)(width / resolution), width an int_t parameter in m."""
        res = self.resolution
        return (
            int(ros_int(self.get("width", 10)) / res),
            int(ros_int(self.get("height", 10)) / res),
        )

    def layers_of(self, kind: str) -> list[Layer]:
        return [layer for layer in self.layers if layer.kind == kind]

    def sources(self) -> list[Source]:
        return [s for layer in self.layers_of("obstacle") for s in layer.sources]

    def footprint(self) -> list[tuple[float, float]]:
        """The padded footprint (footprint.cpp makeFootprintFromParams + padFootprint)."""
        points = parse_footprint(search(self.chain, "footprint"))
        if points is None:
            radius = search(self.chain, "robot_radius")
            radius = 0.46 if radius is None else float(radius)
            points = [
                (radius * math.cos(2 * math.pi * i / 16), radius * math.sin(2 * math.pi * i / 16))
                for i in range(16)
            ]
        pad = float(self.get("footprint_padding", 0.01))

        def sign0(v: float) -> float:
            return 0.0 if v == 0.0 else math.copysign(1.0, v)

        return [(x + sign0(x) * pad, y + sign0(y) * pad) for x, y in points]

    def inscribed_radius(self) -> float:
        fp = self.footprint()
        return min(
            min(math.hypot(*fp[i]), _segment_distance(*fp[i], *fp[(i + 1) % len(fp)]))
            for i in range(len(fp))
        )

    def circumscribed_radius(self) -> float:
        return max(math.hypot(x, y) for x, y in self.footprint())


@dataclass
class Inflation:
    """costmap_2d's InflationLayer costs for one costmap resolution (inflation_layer.h)."""

    inflation_radius: float
    cost_scaling_factor: float
    inscribed_radius: float
    resolution: float
    # costmap_2d inflates to ceil(radius / resolution) cells; our InflationLayer to the radius
    # itself (docs/migrating.md, `inflation_radius`): they differ when the radius is not a whole
    # number of cells (Ridgeback: 0.25 m at 0.1 m).
    ceil_cells: bool = True

    @property
    def cell_radius(self) -> int:
        """Costmap2D::cellDistance: cells farther than this (in cells) get no cost."""
        return int(max(0.0, math.ceil(self.inflation_radius / self.resolution)))

    def cost(self, distance_cells: float) -> int:
        """computeCost(distance in cells), 0 beyond cell_radius (ceil_cells) or beyond the
        radius itself (our host, to within its 1e-6 relative tolerance)."""
        if distance_cells > self.cell_radius:
            return FREE
        if not self.ceil_cells and distance_cells * self.resolution > self.inflation_radius * (
            1.0 + 1e-6
        ):
            return FREE
        if distance_cells == 0:
            return LETHAL
        if distance_cells * self.resolution <= self.inscribed_radius:
            return INSCRIBED
        factor = math.exp(
            -1.0
            * self.cost_scaling_factor
            * (distance_cells * self.resolution - self.inscribed_radius)
        )
        return int((INSCRIBED - 1) * factor)


def inflation_of(costmap: Costmap, resolution: float, ceil_cells: bool = True) -> Inflation | None:
    """The costs of the costmap's first inflation layer (ceil_cells=False: our host's rule)."""
    layers = costmap.layers_of("inflation")
    if not layers:
        return None
    layer = layers[0]
    return Inflation(
        inflation_radius=float(layer.get("inflation_radius", 0.55)),
        cost_scaling_factor=float(layer.get("cost_scaling_factor", 10.0)),
        inscribed_radius=costmap.inscribed_radius(),
        resolution=resolution,
        ceil_cells=ceil_cells,
    )


@dataclass
class Box:
    """An axis-aligned box obstacle (m, map frame) the lidar sees and the static map lacks."""

    cx: float
    cy: float
    half: float

    def segments(self) -> np.ndarray:
        x0, x1, y0, y1 = (
            self.cx - self.half,
            self.cx + self.half,
            self.cy - self.half,
            self.cy + self.half,
        )
        return np.array(
            [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]],
            dtype=np.float64,
        )


@dataclass
class SensorSpec:
    """One simulated sensor: a topic with its message type, frame and height above the base."""

    topic: str
    data_type: str
    frame: str
    height: float


@dataclass
class Scene:
    """The test world for one robot, every number derived from its costmaps (map frame, m)."""

    map_resolution: float
    map_origin: tuple[float, float]
    map_cells: np.ndarray  # int8 (rows, cols): 0 free, 100 wall, -1 unknown
    map_topics: list[str]
    wall_segments: np.ndarray  # (M, 4) centre lines of the map's wall cells, for the lidar
    near: Box  # within every source's obstacle_range: must be lethal
    far: Box  # beyond every source's obstacle_range: must not be
    probe_wall_y: float  # y of the interior wall's cell centres (static-layer inflation probes)
    odom_in_map: tuple[float, float]  # map -> odom translation
    start: tuple[float, float]  # robot in map
    move: tuple[float, float]  # the rolling-window step
    sensors: list[SensorSpec]
    base_frame: str

    def world_segments(self) -> np.ndarray:
        return np.vstack([self.wall_segments, self.near.segments(), self.far.segments()])


def costmaps_of(tree: Params) -> tuple[Costmap, Costmap]:
    return Costmap.from_tree(tree, "global_costmap"), Costmap.from_tree(tree, "local_costmap")


def sensor_height(costmaps: list[Costmap], topic: str) -> float:
    """A height where every source reading `topic` can mark: the middle of the intersection of
    their height bands, the layers' max_obstacle_height and voxel columns, at most 1 m."""
    lo, hi = -math.inf, math.inf
    for cm in costmaps:
        for layer in cm.layers_of("obstacle"):
            bottom, top = layer.z_band()
            for s in layer.sources:
                if s.topic == topic:
                    lo = max(lo, s.min_obstacle_height, bottom, 0.0)
                    hi = min(hi, s.max_obstacle_height, top)
    if not math.isfinite(lo) or not math.isfinite(hi) or hi < lo:
        return 0.2
    return min(0.5 * (lo + hi), 1.0) if hi - lo > 1e-9 else lo


def build_scene(tree: Params) -> Scene:
    """The map, boxes and sensors for this pair: the near box sits at 60 % of the shortest
    obstacle_range (and inside every local window), the far box 0.6 m beyond the longest one at
    45 degrees, the interior wall below the robot further than any inflation radius from both."""
    costmaps = list(costmaps_of(tree))
    sources = [s for cm in costmaps for s in cm.sources()]
    ranges = [s.obstacle_range for s in sources if s.marking] or [2.5]
    radii = [
        float(layer.get("inflation_radius", 0.55))
        for cm in costmaps
        for layer in cm.layers_of("inflation")
    ] or [0.55]
    infl = max(radii)
    reach = max(cm.circumscribed_radius() for cm in costmaps)
    local_half = min(
        [0.5 * min(cm.size_cells()) * cm.resolution for cm in costmaps if cm.rolling] or [10.0]
    )
    half = 0.15
    d_near = max(0.6 * min(min(ranges), local_half - 2 * half), reach + 0.15)
    d_far = max(ranges) + 0.6
    yaml_res = {cm.resolution for cm in costmaps}
    res = 0.1 if 0.1 not in yaml_res else 0.08
    # Room: the far box plus the inflation radius and a metre of air; never the YAML's size.
    extent = max(d_far + 2 * half, d_near + 2 * half, local_half) + infl + 1.0
    x_min, x_max = -extent - 0.37, extent + 0.21
    y_min, y_max = -extent - 0.53, extent + 0.11
    cols = int(math.ceil((x_max - x_min) / res))
    rows = int(math.ceil((y_max - y_min) / res))
    origin = (round(x_min, 6), round(y_min, 6))
    cells = np.zeros((rows, cols), dtype=np.int8)
    cells[0, :] = cells[-1, :] = cells[:, 0] = cells[:, -1] = 100
    # Interior wall below the robot, further than any radius from it and from the outer wall.
    wall_row = int(math.floor((-(infl + reach + 0.8) - origin[1]) / res))
    wall_row = max(wall_row, int(math.ceil((infl + 0.5) / res)) + 1)
    c0, c1 = int(cols * 0.25), int(cols * 0.75)
    cells[wall_row, c0:c1] = 100
    # An unknown corner (top-left) as map_server writes unexplored space.
    cells[rows - 1 - rows // 6 : rows - 1, 1 : 1 + cols // 6] = -1

    def cx(i: float) -> float:
        return origin[0] + (i + 0.5) * res

    def cy(j: float) -> float:
        return origin[1] + (j + 0.5) * res

    segs = [
        [cx(0), cy(0), cx(cols - 1), cy(0)],
        [cx(cols - 1), cy(0), cx(cols - 1), cy(rows - 1)],
        [cx(cols - 1), cy(rows - 1), cx(0), cy(rows - 1)],
        [cx(0), cy(rows - 1), cx(0), cy(0)],
        [cx(c0) - 0.5 * res, cy(wall_row), cx(c1 - 1) + 0.5 * res, cy(wall_row)],
    ]
    diag = (d_far + half) / math.sqrt(2.0)
    map_topics = sorted(
        {
            resolve_topic(str(layer.get("map_topic", "map")))
            for cm in costmaps
            for layer in cm.layers_of("static")
        }
    )
    base = costmaps[0].robot_base_frame.lstrip("/")
    sensors: dict[str, SensorSpec] = {}
    for s in sources:
        if s.topic not in sensors:
            frame = s.sensor_frame.lstrip("/") or f"sim_{s.name}"
            sensors[s.topic] = SensorSpec(
                s.topic, s.data_type, frame, sensor_height(costmaps, s.topic)
            )
    step = min(1.0, 0.4 * local_half)
    return Scene(
        map_resolution=res,
        map_origin=origin,
        map_cells=cells,
        map_topics=map_topics,
        wall_segments=np.asarray(segs, dtype=np.float64),
        near=Box(d_near + half, 0.0, half),
        far=Box(diag, diag, half),
        probe_wall_y=cy(wall_row),
        odom_in_map=(0.3, -0.2),
        start=(0.0, 0.0),
        move=(-step, 0.5 * step),
        sensors=list(sensors.values()),
        base_frame=base,
    )
