"""move_base_config (the real-config rostests' reading of a move_base YAML pair) restates
costmap_2d: parameter moves, plugin lists, key lookups, footprint, inflation formula."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "rostest" / "real_configs"))

import move_base_config as mbc  # noqa: E402

CONFIGS = ROOT / "rostest" / "real_configs"
PAIRS = {
    "turtlebot3_waffle": (
        "costmap_common_params_waffle.yaml",
        "global_costmap_params.yaml",
        "local_costmap_params.yaml",
        "",
        "",
        "",
    ),
    "husky": (
        "costmap_common.yaml",
        "costmap_global_static.yaml",
        "costmap_local.yaml",
        "global_costmap",
        "local_costmap",
        "",
    ),
    "jackal": (
        "costmap_common_params.yaml",
        "global_costmap_params.yaml",
        "local_costmap_params.yaml",
        "",
        "",
        "",
    ),
    "turtlebot": (
        "costmap_common_params.yaml",
        "global_costmap_params.yaml",
        "local_costmap_params.yaml",
        "",
        "",
        "move_base_launch_params.yaml",
    ),
    "mir": (
        "costmap_common_params.yaml",
        "costmap_global_params.yaml",
        "costmap_local_params.yaml",
        "",
        "",
        "move_base_launch_params.yaml",
    ),
    "ridgeback": (
        "costmap_common_params.yaml",
        "global_costmap_params.yaml",
        "local_costmap_params.yaml",
        "",
        "",
        "",
    ),
    "freight": (
        "costmap_common.yaml",
        "costmap_global.yaml",
        "costmap_local.yaml",
        "global_costmap",
        "local_costmap",
        "",
    ),
}
# root, global_more, local_more, common_more: files loaded besides the pair (real_configs.launch's
# args).
MORE = {
    "mir": (
        "move_base_common_params.yaml",
        "costmap_global_params_plugins_no_virtual_walls.yaml",
        "costmap_local_params_plugins_no_virtual_walls.yaml",
        "",
    ),
    "freight": (
        "",
        "freight_costmap_global.yaml",
        "freight_costmap_local.yaml",
        "freight_costmap_common.yaml",
    ),
}


def tree_of(robot: str) -> mbc.Params:
    common, glob, local, gns, lns, extra = PAIRS[robot]
    d = CONFIGS / robot
    root, gmore, lmore, cmore = (str(d / f) if f else "" for f in MORE.get(robot, ("", "", "", "")))
    return mbc.load_pair(
        str(d / common),
        str(d / glob),
        str(d / local),
        gns,
        lns,
        str(d / extra) if extra else "",
        root,
        gmore,
        lmore,
        cmore,
    )


def test_root_and_more_files_like_mir_launch() -> None:
    """MiR: the plugins lists come from the *_more files, the footprint from move_base's own file
    at the root (searchParam), and each costmap keeps its own ranges and voxel columns."""
    glob, local = mbc.costmaps_of(tree_of("mir"))
    assert [layer.name for layer in glob.layers] == ["navigation_map", "obstacles", "inflation"]
    assert [layer.name for layer in local.layers] == ["obstacles", "inflation"]
    assert glob.footprint() == local.footprint()
    assert glob.footprint()[0] == (0.488, -0.293)
    assert (glob.robot_base_frame, local.global_frame) == ("base_footprint", "odom")
    assert {s.raytrace_range for s in glob.sources()} == {2.0}
    assert {s.raytrace_range for s in local.sources()} == {6.0}
    assert {s.obstacle_range for s in local.sources()} == {3.0}
    assert [s.marking for s in local.sources()] == [True, False, True, False]


def test_common_plugins_replaced_by_the_global_list_like_ridgeback() -> None:
    """Ridgeback: the common file's plugins list reaches both costmaps; the global file's list
    replaces it there (rosparam load replaces a list), the local costmap keeps it."""
    glob, local = mbc.costmaps_of(tree_of("ridgeback"))
    assert [layer.name for layer in glob.layers] == [
        "static_layer",
        "obstacles_layer",
        "inflater_layer",
    ]
    assert [layer.name for layer in local.layers] == ["obstacles_layer", "inflater_layer"]
    (src,) = local.sources()
    assert (src.topic, src.sensor_frame, src.obstacle_range) == ("/front/scan", "front_laser", 2.5)
    assert local.rolling and local.global_frame == "map"


def test_common_more_file_like_fetch_launch() -> None:
    """Freight: the per-robot common file (common_more) adds the source to both costmaps, the
    per-robot costmap files the plugins lists; the VoxelLayer without voxel keys takes
    costmap_2d's defaults (10 voxels of 0.2 m from 0)."""
    glob, local = mbc.costmaps_of(tree_of("freight"))
    assert [layer.name for layer in glob.layers] == ["static_map", "obstacles", "inflater"]
    assert [layer.name for layer in local.layers] == ["obstacles", "inflater"]
    assert glob.layers[1].z_band() == (0.0, 0.2 * 10)
    assert {(s.obstacle_range, s.raytrace_range) for s in local.sources()} == {(6.0, 10.0)}
    assert local.rolling and local.size_cells() == (160, 160)


def test_merge_unrolls_dictionaries_like_roslaunch() -> None:
    tree: mbc.Params = {}
    mbc.merge(tree, "a", {"b": {"c": 1, "d": [1, 2]}})
    mbc.merge(tree, "", {"a": {"b": {"c": 2}}})
    assert tree == {"a": {"b": {"c": 2, "d": [1, 2]}}}


def test_pre_hydro_list_and_moves() -> None:
    """turtlebot3: no plugins, static_map true: costmap_2d's three generated layers, the ranges
    and the source moved into obstacle_layer, the inflation keys into inflation_layer."""
    glob, local = mbc.costmaps_of(tree_of("turtlebot3_waffle"))
    assert [(layer.name, layer.type) for layer in glob.layers] == [
        ("static_layer", "costmap_2d::StaticLayer"),
        ("obstacle_layer", "costmap_2d::ObstacleLayer"),
        ("inflation_layer", "costmap_2d::InflationLayer"),
    ]
    assert [layer.name for layer in local.layers] == ["obstacle_layer", "inflation_layer"]
    assert "obstacle_range" not in glob.params  # moved, not copied
    (src,) = glob.sources()
    assert (src.topic, src.sensor_frame, src.obstacle_range, src.raytrace_range) == (
        "/scan",
        "base_scan",
        3.0,
        3.5,
    )
    inflation = glob.layers_of("inflation")[0]
    assert (inflation.get("inflation_radius", 0), inflation.get("cost_scaling_factor", 0)) == (
        1.0,
        3.0,
    )
    assert local.rolling and local.size_cells() == (int(3 / 0.05), int(3 / 0.05))


def test_voxel_map_type_generates_voxel_layer() -> None:
    tree = {
        "global_costmap": {"map_type": "voxel", "z_voxels": 4, "observation_sources": "s", "s": {}}
    }
    glob = mbc.Costmap.from_tree(tree, "global_costmap")
    assert [layer.type for layer in glob.layers] == [
        "costmap_2d::VoxelLayer",
        "costmap_2d::InflationLayer",
    ]
    assert glob.layers[0].z_band() == (0.0, 0.2 * 4)
    assert glob.sources()[0].data_type == "PointCloud"  # costmap_2d's default data_type


def test_plugins_copy_parent_parameters_over_the_layer() -> None:
    """copyParentParameters overwrites the layer's own key with the costmap's."""
    tree = {
        "c": {
            "inflation_radius": 0.9,
            "plugins": [{"name": "infl", "type": "costmap_2d::InflationLayer"}],
            "infl": {"inflation_radius": 0.2},
        }
    }
    cm = mbc.Costmap.from_tree(tree, "c")
    assert cm.layers[0].get("inflation_radius", 0) == 0.9


def test_source_keys_are_searched_upward() -> None:
    """husky: obstacle_range set at the costmap level reaches the source (searchParam), the
    topic is relative (resolved at the root), costmap_2d's defaults fill the rest."""
    _, local = mbc.costmaps_of(tree_of("husky"))
    (src,) = local.sources()
    assert (src.topic, src.obstacle_range, src.raytrace_range, src.inf_is_valid) == (
        "/front/scan",
        5.5,
        6.0,
        True,
    )
    assert (src.min_obstacle_height, src.max_obstacle_height) == (0.0, 2.0)
    tree = {
        "c": {
            "plugins": [{"name": "o", "type": "costmap_2d::ObstacleLayer"}],
            "o": {"observation_sources": "x"},
        }
    }
    (src,) = mbc.Costmap.from_tree(tree, "c").sources()
    assert (src.topic, src.obstacle_range, src.raytrace_range, src.clearing) == (
        "/x",
        2.5,
        3.0,
        False,
    )


def test_footprint_and_inscribed_radius() -> None:
    square = {"c": {"footprint": [[-0.25, -0.25], [-0.25, 0.25], [0.25, 0.25], [0.25, -0.25]]}}
    cm = mbc.Costmap.from_tree(square, "c")
    assert cm.inscribed_radius() == pytest.approx(0.26)  # default footprint_padding 0.01
    square["c"]["footprint_padding"] = 0.0
    square["c"]["footprint"] = "[[-0.25, -0.25], [-0.25, 0.25], [0.25, 0.25], [0.25, -0.25]]"
    assert mbc.Costmap.from_tree(square, "c").inscribed_radius() == pytest.approx(0.25)
    round_robot = mbc.Costmap.from_tree({"c": {"robot_radius": 0.2, "footprint_padding": 0.0}}, "c")
    assert round_robot.inscribed_radius() == pytest.approx(0.2 * math.cos(math.pi / 16))
    # padding leaves a coordinate that is exactly 0 where it is
    pad = mbc.Costmap.from_tree({"c": {"footprint": [[0.46, 0.0], [0, 1], [-1, 0]]}}, "c")
    assert pad.footprint()[0] == pytest.approx((0.47, 0.0)) and pad.footprint()[0][1] == 0.0


def test_inflation_formula_and_translation() -> None:
    """docs/costmap.md's example (0.2 m inscribed, factor 3, 5 cm): 253 / 186 / 138 at 4 / 6 / 8."""
    inf = mbc.Inflation(
        inflation_radius=0.55, cost_scaling_factor=3.0, inscribed_radius=0.2, resolution=0.05
    )
    assert [inf.cost(d) for d in (0, 4, 6, 8)] == [254, 253, 186, 138]
    assert inf.cell_radius == 11 and inf.cost(11) > 0 and inf.cost(11.05) == 0
    assert [mbc.translate(c) for c in (0, 1, 128, 252, 253, 254, 255)] == [
        0,
        1,
        50,
        98,
        99,
        100,
        -1,
    ]


def test_inflation_radius_rule_of_each_host() -> None:
    """Ridgeback's 0.25 m at 0.1 m: costmap_2d inflates to ceil = 3 cells, our host to 2.5 cells
    (docs/migrating.md); a whole number of cells is the same for both."""
    theirs = mbc.Inflation(0.25, 10.0, 0.5, 0.1)
    ours = mbc.Inflation(0.25, 10.0, 0.5, 0.1, ceil_cells=False)
    assert (theirs.cost(3), ours.cost(3), ours.cost(2.5), ours.cost(math.sqrt(5))) == (
        253,
        0,
        253,
        253,
    )
    whole = [mbc.Inflation(0.3, 10.0, 0.1, 0.1, ceil_cells=c) for c in (True, False)]
    assert [w.cost(3) for w in whole] == [whole[0].cost(3)] * 2 and whole[0].cost(3) > 0


def test_ros_int_rounds_like_roscpp() -> None:
    assert [mbc.ros_int(v) for v in (4.0, 4.4, 4.5, 10)] == [4, 4, 5, 10]


@pytest.mark.parametrize("robot", sorted(PAIRS))
def test_scene_matches_the_config(robot: str) -> None:
    """The map differs from the YAML's size and resolution, the near box is inside every
    marking source's obstacle_range and the far box beyond all of them, and every sensor sits
    inside its sources' height bands."""
    tree = tree_of(robot)
    costmaps = mbc.costmaps_of(tree)
    scene = mbc.build_scene(tree)
    for cm in costmaps:
        assert scene.map_resolution != cm.resolution
        assert scene.map_cells.shape[::-1] != cm.size_cells()
    ranges = [s.obstacle_range for cm in costmaps for s in cm.sources()]
    assert scene.near.cx - scene.near.half < min(ranges)
    assert math.hypot(scene.far.cx, scene.far.cy) - scene.far.half * math.sqrt(2) > max(ranges)
    assert (scene.map_cells == 100).any() and (scene.map_cells == -1).any()
    for spec in scene.sensors:
        for cm in costmaps:
            for s in cm.sources():
                if s.topic == spec.topic:
                    assert s.min_obstacle_height <= spec.height <= s.max_obstacle_height
