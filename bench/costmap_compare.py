#!/usr/bin/env python3
"""Cell-by-cell comparison of two costmap hosts run on the same simulated world (issue 18: the
real move_base configs in costmap_2d's Costmap2DROS and in our nodelet). Two subcommands:

capture (a ROS node, in a sourced workspace, next to a running host and real_config_sim.py):
    costmap_compare.py capture --prefix /move_base --scan-topic /front/scan --out a.npz
  follows <prefix>/global_costmap/costmap and <prefix>/local_costmap/costmap (full grid plus
  _updates applied, as move_base does) and the static map, counts the scans published on
  --scan-topic from the moment both costmaps have been received, and at each count in --scans
  (default 5,30,100) saves both grids, their origins in the map frame (tf at that moment) and
  the last scan's end points (map frame) into --out (one npz, keys prefixed n<count>_).

compare (offline, numpy only):
    costmap_compare.py compare ours.npz theirs.npz [--at 100] [--markdown]
  aligns each pair of grids by their map-frame origins (a rolling window may sit a cell apart)
  and prints, per costmap, the cells equal / different by class (lethal 100, inscribed 99,
  inflated 1..98, free 0, unknown -1), the confusion between the classes, and for the
  differing cells a cause: the static map's value there, whether a scan ended in the cell or a
  ray crossed it, and for an inflated difference whether both grids put the nearest lethal cell
  at the same distance (then the difference is the inflation itself, not its input).

Nothing here builds or fetches costmap_2d.
"""

from __future__ import annotations

import argparse
import sys
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

CLASSES = ("lethal", "inscribed", "inflated", "free", "unknown")
COSTMAPS = ("global_costmap", "local_costmap")


def classify(grid: np.ndarray) -> np.ndarray:
    """Class index (into CLASSES) of every cell of an OccupancyGrid-valued array."""
    out = np.full(grid.shape, 2, dtype=np.int8)
    out[grid == 100] = 0
    out[grid == 99] = 1
    out[grid == 0] = 3
    out[grid < 0] = 4
    return out


# --------------------------------------------------------------------------------- capture


def capture(args: argparse.Namespace) -> int:
    import rospy
    import tf2_ros
    from nav_msgs.msg import OccupancyGrid
    from sensor_msgs.msg import LaserScan

    from downstream_perception.ros.costmap_client import CostmapClient

    rospy.init_node("costmap_compare_capture", anonymous=True)
    clients = {ns: CostmapClient(f"{args.prefix}/{ns}/costmap") for ns in COSTMAPS}
    buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(buffer)
    state: dict[str, Any] = {"count": 0, "scan": None, "map": None, "counting": False}
    lock = threading.Lock()

    def on_scan(msg: LaserScan) -> None:
        with lock:
            if state["counting"]:
                state["count"] += 1
            state["scan"] = msg

    def on_map(msg: OccupancyGrid) -> None:
        with lock:
            state["map"] = msg

    rospy.Subscriber(args.scan_topic, LaserScan, on_scan, queue_size=50)
    rospy.Subscriber(args.map_topic, OccupancyGrid, on_map, queue_size=1)
    deadline = time.time() + args.timeout
    while not all(c.received for c in clients.values()):
        if rospy.is_shutdown() or time.time() > deadline:
            print("capture: costmaps not received", file=sys.stderr)
            return 1
        time.sleep(0.05)
    with lock:
        state["counting"] = True
    saved: dict[str, np.ndarray] = {}
    for n in sorted(int(s) for s in args.scans.split(",")):
        while True:
            with lock:
                if state["count"] >= n:
                    break
            if rospy.is_shutdown() or time.time() > deadline:
                print(f"capture: only {state['count']} scans", file=sys.stderr)
                return 1
            time.sleep(0.005)
        with lock:
            scan = state["scan"]
            grid_map = state["map"]
        for ns, client in clients.items():
            msg = client.message()
            grid = np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
            frame = msg.header.frame_id.lstrip("/")
            tr = buffer.lookup_transform("map", frame, rospy.Time(0), rospy.Duration(1.0))
            t = tr.transform.translation
            o = msg.info.origin.position
            saved[f"n{n}_{ns}_grid"] = grid
            saved[f"n{n}_{ns}_origin"] = np.array([o.x + t.x, o.y + t.y])
            saved[f"n{n}_{ns}_resolution"] = np.array(msg.info.resolution)
            saved[f"n{n}_{ns}_updates"] = np.array([client.full_grids, client.updates])
        if scan is not None:
            tr = buffer.lookup_transform(
                "map", scan.header.frame_id.lstrip("/"), rospy.Time(0), rospy.Duration(1.0)
            )
            t = tr.transform.translation
            r = np.asarray(scan.ranges, dtype=np.float64)
            a = scan.angle_min + scan.angle_increment * np.arange(len(r))
            ok = np.isfinite(r)
            saved[f"n{n}_sensor"] = np.array([t.x, t.y])
            saved[f"n{n}_hits"] = np.stack(
                [t.x + r[ok] * np.cos(a[ok]), t.y + r[ok] * np.sin(a[ok])], axis=1
            )
        print(f"capture: {n} scans saved", flush=True)
    if grid_map is not None:
        o = grid_map.info.origin.position
        saved["map_grid"] = np.asarray(grid_map.data, dtype=np.int8).reshape(
            grid_map.info.height, grid_map.info.width
        )
        saved["map_origin"] = np.array([o.x, o.y])
        saved["map_resolution"] = np.array(grid_map.info.resolution)
    np.savez_compressed(args.out, **saved)
    return 0


# --------------------------------------------------------------------------------- compare


class Grid:
    def __init__(self, data: Any, key: str) -> None:
        self.grid = data[f"{key}_grid"]
        self.origin = data[f"{key}_origin"].astype(np.float64)
        self.res = float(data[f"{key}_resolution"])

    def centres(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return (
            self.origin[0] + (cols + 0.5) * self.res,
            self.origin[1] + (rows + 0.5) * self.res,
        )


def lookup(g: Grid, x: np.ndarray, y: np.ndarray, outside: int) -> np.ndarray:
    """g's value at the map-frame points, `outside` off its grid."""
    c = np.floor((x - g.origin[0]) / g.res + 1e-9).astype(int)
    r = np.floor((y - g.origin[1]) / g.res + 1e-9).astype(int)
    h, w = g.grid.shape
    ok = (c >= 0) & (r >= 0) & (c < w) & (r < h)
    out = np.full(x.shape, outside, dtype=np.int16)
    out[ok] = g.grid[r[ok], c[ok]]
    return out


def nearest_lethal_cells(grid: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Euclidean distance (cells) from each (row, col) to the nearest lethal cell of grid."""
    lethal = np.argwhere(grid == 100)
    if not len(lethal):
        return np.full(rows.shape, np.inf)
    out = np.empty(rows.shape)
    for k in range(0, len(rows), 2048):
        dr = rows[k : k + 2048, None] - lethal[None, :, 0]
        dc = cols[k : k + 2048, None] - lethal[None, :, 1]
        out[k : k + 2048] = np.sqrt((dr * dr + dc * dc).min(axis=1))
    return out


def ray_crossed(
    sensor: np.ndarray, hits: np.ndarray, x: np.ndarray, y: np.ndarray, res: float
) -> np.ndarray:
    """True where a cell centre lies within half a cell of a ray sensor -> hit (before it)."""
    out = np.zeros(x.shape, dtype=bool)
    px, py = x - sensor[0], y - sensor[1]
    for k in range(0, len(hits), 64):
        d = hits[k : k + 64] - sensor
        length = np.hypot(d[:, 0], d[:, 1])[:, None]
        ux, uy = d[:, 0:1] / length, d[:, 1:2] / length
        along = px[None, :] * ux + py[None, :] * uy
        across = np.abs(px[None, :] * uy - py[None, :] * ux)
        near = (across <= 0.5 * res) & (along > 0) & (along < length - 0.5 * res)
        out |= near.any(axis=0)
    return out


def cause_of(a: int, b: int, map_value: int, hit: bool, crossed: bool, same_distance: bool) -> str:
    """A short cause label for one differing cell (a = ours, b = theirs, class indices)."""
    where = (
        "map wall"
        if map_value == 100
        else "map unknown"
        if map_value < 0 and map_value > -200
        else "off map"
        if map_value <= -200
        else "scan end"
        if hit
        else "on a ray"
        if crossed
        else "elsewhere"
    )
    if {a, b} <= {1, 2, 3}:  # inscribed / inflated / free: only the inflation differs
        kind = "inflation (same nearest lethal)" if same_distance else "inflation (input differs)"
        return f"{kind}, {where}"
    return f"{CLASSES[a]} vs {CLASSES[b]}, {where}"


def compare_one(ours: Grid, theirs: Grid, data: Any, n: int) -> dict[str, Any]:
    if abs(ours.res - theirs.res) > 1e-6:
        return {"error": f"resolutions differ: {ours.res} vs {theirs.res}"}
    shift = (theirs.origin - ours.origin) / ours.res
    rows, cols = np.indices(ours.grid.shape)
    rows, cols = rows.ravel(), cols.ravel()
    x, y = ours.centres(rows, cols)
    b_val = lookup(theirs, x, y, outside=-300)
    inside = b_val > -300
    rows, cols, x, y, b_val = rows[inside], cols[inside], x[inside], y[inside], b_val[inside]
    a_val = ours.grid[rows, cols].astype(np.int16)
    a_cls, b_cls = classify(a_val), classify(b_val)
    diff = a_val != b_val
    result: dict[str, Any] = {
        "shape": (ours.grid.shape, theirs.grid.shape),
        "origin_shift_cells": np.round(shift, 3).tolist(),
        "compared": int(inside.sum()),
        "equal": int((~diff).sum()),
        "different": int(diff.sum()),
        "per_class": {},
        "confusion": Counter(),
        "causes": Counter(),
    }
    for k, name in enumerate(CLASSES):
        result["per_class"][name] = (
            int((a_cls == k).sum()),
            int((b_cls == k).sum()),
            int(((a_cls == k) & (b_cls == k) & ~diff).sum()),
        )
    idx = np.nonzero(diff)[0]
    if not len(idx):
        return result
    for i in idx:
        result["confusion"][(CLASSES[a_cls[i]], CLASSES[b_cls[i]])] += 1
    if "map_grid" in data:
        m = Grid(data, "map")
        map_v = lookup(m, x[idx], y[idx], outside=-300)
    else:
        map_v = np.zeros(len(idx), dtype=np.int16)
    hits = data.get(f"n{n}_hits") if hasattr(data, "get") else None
    if hits is not None and len(hits):
        hc = np.floor((hits[:, 0] - ours.origin[0]) / ours.res).astype(int)
        hr = np.floor((hits[:, 1] - ours.origin[1]) / ours.res).astype(int)
        hit_cells = set(zip(hr.tolist(), hc.tolist(), strict=True))
        is_hit = np.array([(r, c) in hit_cells for r, c in zip(rows[idx], cols[idx], strict=True)])
        crossed = ray_crossed(data[f"n{n}_sensor"], hits, x[idx], y[idx], ours.res)
    else:
        is_hit = np.zeros(len(idx), dtype=bool)
        crossed = np.zeros(len(idx), dtype=bool)
    da = nearest_lethal_cells(ours.grid, rows[idx], cols[idx])
    # theirs in our cell indices: same resolution, origin shifted by `shift` cells
    tr = rows[idx] - int(round(shift[1]))
    tc = cols[idx] - int(round(shift[0]))
    db = nearest_lethal_cells(theirs.grid, tr, tc)
    for j, i in enumerate(idx):
        result["causes"][
            cause_of(
                int(a_cls[i]),
                int(b_cls[i]),
                int(map_v[j]),
                bool(is_hit[j]),
                bool(crossed[j]),
                bool(abs(da[j] - db[j]) < 1e-6),
            )
        ] += 1
    return result


def print_result(title: str, r: dict[str, Any], markdown: bool) -> None:
    print(f"\n### {title}")
    if "error" in r:
        print(r["error"])
        return
    total = r["compared"]
    print(
        f"grids {r['shape'][0]} (ours) / {r['shape'][1]} (theirs), origin shift "
        f"{r['origin_shift_cells']} cells; {total} cells compared: {r['equal']} equal "
        f"({100.0 * r['equal'] / max(total, 1):.2f} %), {r['different']} different"
    )
    if markdown:
        print("\n| class | ours | theirs | equal in both |\n|---|---:|---:|---:|")
        for name, (a, b, eq) in r["per_class"].items():
            print(f"| {name} | {a} | {b} | {eq} |")
    else:
        for name, (a, b, eq) in r["per_class"].items():
            print(f"  {name:10s} ours {a:7d}  theirs {b:7d}  equal {eq:7d}")
    if r["confusion"]:
        print(
            "differences (ours -> theirs): "
            + ", ".join(f"{a}->{b} {k}" for (a, b), k in r["confusion"].most_common())
        )
        print("causes: " + "; ".join(f"{c}: {k}" for c, k in r["causes"].most_common()))


def compare(args: argparse.Namespace) -> int:
    ours = np.load(args.ours)
    theirs = np.load(args.theirs)
    data = dict(theirs)  # the map and the scan: the same simulator feeds both runs
    if "map_grid" in ours and "map_grid" in theirs:
        same_map = np.array_equal(ours["map_grid"], theirs["map_grid"])
        print(f"static map identical in both runs: {same_map}")
    for ns in COSTMAPS:
        key = f"n{args.at}_{ns}"
        if f"{key}_grid" not in ours or f"{key}_grid" not in theirs:
            print(f"\n### {ns}: not captured at {args.at} scans")
            continue
        r = compare_one(Grid(ours, key), Grid(theirs, key), data, args.at)
        print_result(f"{args.title}{ns} after {args.at} scans", r, args.markdown)
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("capture")
    c.add_argument("--prefix", default="", help="'' for our nodelets, /move_base for costmap_2d")
    c.add_argument("--scan-topic", required=True)
    c.add_argument("--map-topic", default="/map")
    c.add_argument("--scans", default="5,30,100")
    c.add_argument("--timeout", type=float, default=120.0, help="s, for the whole capture")
    c.add_argument("--out", type=Path, required=True)
    k = sub.add_parser("compare")
    k.add_argument("ours", type=Path)
    k.add_argument("theirs", type=Path)
    k.add_argument("--at", type=int, default=100, help="the scan count to compare")
    k.add_argument("--title", default="")
    k.add_argument("--markdown", action="store_true")
    args = p.parse_args(rospy_args(argv))
    return capture(args) if args.cmd == "capture" else compare(args)


def rospy_args(argv: list[str] | None) -> list[str]:
    """argv without roslaunch's __name:= / __log:= remappings."""
    return [a for a in (sys.argv[1:] if argv is None else argv) if ":=" not in a]


if __name__ == "__main__":
    sys.exit(main())
