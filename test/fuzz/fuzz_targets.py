"""The fuzz targets of make fuzz: every entry point of the compiled module
(downstream_perception._core) and every nodelet message check (through the C++ driver
fuzz_message_checks).

Each target generates hostile arguments (NaN, +-Inf, 0, -0, negative, 1e18, 1e300, 5e-324,
extreme ints, wrong shapes and dtypes, empty and mismatched arrays) mixed with plausible ones,
so that the plausible part gets past the first check and the hostile part reaches the code
behind it. Its garbage check says what output the inputs make invalid; where the C++ documents
that it refuses invalid settings ("throws std::invalid_argument if the config is invalid"),
accepting them is garbage too.
"""

from __future__ import annotations

import dataclasses
import io
import math
import os
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from fuzz_harness import HarnessError, Target, TargetCrashed

NAN = float("nan")
INF = float("inf")
NASTY_FLOATS = (
    NAN, INF, -INF, 0.0, -0.0, -1.0, 1e18, -1e18, 1e300, -1e300, 5e-324, -5e-324,
    1e-9, 2e-5, 2.0**31, 2.0**63, 1.7976931348623157e308,
)  # fmt: skip
NASTY_INTS = (0, -1, 1, 2**31 - 1, -(2**31), 2**31, 2**63, -(2**63), 2**64, 10**6, 10**9)
INT32_NASTY = (0, -1, 1, 2**31 - 1, -(2**31), 2**30, -(2**30), 10**6)
# Grid sides: invalid ones and the first beyond the per-axis limit, but no valid huge grid (a
# valid 10^6 x 80 grid is legitimately slow and would only make the time limit flaky).
GRID_SIZE_NASTY = (0, -1, 2**31 - 1, -(2**31), 2**31, 2**63, (1 << 22) + 1)
UINT32_NASTY = (0, 1, 2**31 - 1, 2**31, 2**32 - 1, 4_000_000_000, 4000, 3)
PI = math.pi


class Gen:
    """Hostile-or-plausible values from one case's numpy Generator."""

    def __init__(self, rng: np.random.Generator, hostile: float = 0.25) -> None:
        self.rng = rng
        self.hostile = hostile

    def chance(self, p: float) -> bool:
        return bool(self.rng.random() < p)

    def pick(self, options: Sequence[Any]) -> Any:
        return options[int(self.rng.integers(len(options)))]

    def f(self, lo: float, hi: float, p: float | None = None) -> float:
        if self.chance(self.hostile if p is None else p):
            return float(self.pick(NASTY_FLOATS))
        lo, hi = sorted((float(np.clip(lo, -1e300, 1e300)), float(np.clip(hi, -1e300, 1e300))))
        return float(lo + (hi - lo) * self.rng.random()) if hi - lo < INF else lo

    def i(self, lo: int, hi: int, p: float | None = None, nasty: Sequence[int] = NASTY_INTS) -> int:
        if self.chance(self.hostile if p is None else p):
            return int(self.pick(nasty))
        lo, hi = sorted(min(max(v, -(2**62)), 2**62) for v in (lo, hi))
        return int(self.rng.integers(lo, hi + 1))

    def b(self) -> bool:
        return self.chance(0.5)

    def floats(
        self, shape: tuple[int, ...], lo: float, hi: float, p_nasty: float = 0.05
    ) -> np.ndarray:
        a = self.rng.uniform(lo, hi, size=shape)
        if a.size and self.chance(0.5):
            mask = self.rng.random(shape) < p_nasty
            nasty = np.array(NASTY_FLOATS)[self.rng.integers(len(NASTY_FLOATS), size=shape)]
            a = np.where(mask, nasty, a)
        return a

    def array(self, shape: tuple[int, ...], lo: float, hi: float, dtype: Any = np.float64) -> Any:
        """An array of `shape`, or (with the hostile probability) a wrong one: empty, another
        number of dimensions, transposed, strided, another dtype, a list, a string."""
        if not self.chance(self.hostile):
            return self.floats(shape, lo, hi).astype(dtype)
        kind = self.pick(
            ("empty", "ndim+", "ndim-", "transpose", "strided", "int", "bool", "complex",
             "object", "list", "string", "huge_values", "scalar")
        )  # fmt: skip
        base = self.floats(shape, lo, hi)
        if kind == "empty":
            return np.zeros((0, *shape[1:]), dtype=dtype)
        if kind == "ndim+":
            return base.reshape((*shape, 1)).astype(dtype)
        if kind == "ndim-":
            return base.reshape(-1).astype(dtype)
        if kind == "transpose":
            return base.T.astype(dtype)
        if kind == "strided":
            big = np.repeat(base, 2, axis=0).astype(dtype)
            return big[::2]
        if kind == "int":
            return np.nan_to_num(base, posinf=0, neginf=0).astype(np.int64)
        if kind == "bool":
            return base > 0
        if kind == "complex":
            return base.astype(np.complex128)
        if kind == "object":
            return base.astype(object)
        if kind == "list":
            return base.tolist()
        if kind == "string":
            return "not an array"
        if kind == "huge_values":
            return np.full(shape, self.pick((1e300, -1e300, 1e18, 5e-324, NAN, INF)), dtype=dtype)
        return float(self.pick(NASTY_FLOATS))


_CORE: Any = None


def core() -> Any:
    global _CORE
    if _CORE is None:
        from downstream_perception import _core

        _CORE = _core
    return _CORE


def finite(*values: Any) -> bool:
    try:
        return bool(np.all(np.isfinite(np.asarray(values, dtype=float))))
    except (TypeError, ValueError):
        return False


def all_finite(a: Any) -> bool:
    return bool(np.all(np.isfinite(np.asarray(a, dtype=float))))


def configure(obj: Any, fields: dict[str, Any]) -> Any:
    for name, value in fields.items():
        setattr(obj, name, value)
    return obj


# ----------------------------------------------------------------------------- grid geometry
def geometry_args(g: Gen, p_valid: float = 0.85) -> dict[str, Any]:
    if g.chance(p_valid):
        return {
            "size_x": int(g.rng.integers(1, 100)),
            "size_y": int(g.rng.integers(1, 100)),
            "resolution": float(g.pick((0.05, 0.1, 0.025, 0.5, 1.0))),
            "origin_x": float(g.rng.uniform(-10, 10)),
            "origin_y": float(g.rng.uniform(-10, 10)),
        }
    return {
        "size_x": g.i(1, 100, 0.6, GRID_SIZE_NASTY),
        "size_y": g.i(1, 100, 0.6, GRID_SIZE_NASTY),
        "resolution": g.f(0.01, 1.0, 0.6),
        "origin_x": g.f(-10, 10, 0.4),
        "origin_y": g.f(-10, 10, 0.4),
    }


def grid_shape(a: dict[str, Any]) -> tuple[int, int]:
    """(rows, cols) of an array for this grid, kept small when the grid itself is invalid."""
    return (int(np.clip(a["size_y"], 0, 200)), int(np.clip(a["size_x"], 0, 200)))


def make_geometry(a: dict[str, Any]) -> Any:
    return core().GridGeometry(
        a["size_x"], a["size_y"], a["resolution"], a["origin_x"], a["origin_y"]
    )


def geometry_problem(a: dict[str, Any]) -> str | None:
    """Why these grid values are invalid (GridGeometry::validate's rules), or None."""
    sx, sy, res = a["size_x"], a["size_y"], a["resolution"]
    if not (math.isfinite(res) and res > 0):
        return f"resolution {res}"
    if not (0 < sx <= 1 << 22 and 0 < sy <= 1 << 22) or sx * sy > 1 << 28:
        return f"size {sx} x {sy}"
    if not finite(a["origin_x"], a["origin_y"]):
        return "origin not finite"
    return None


def gen_grid_geometry(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.3)
    a = geometry_args(g, 0.6)
    a.update(wx=g.f(-20, 20), wy=g.f(-20, 20), cx=g.i(-5, 105, nasty=INT32_NASTY))
    a["cy"] = g.i(-5, 105, nasty=INT32_NASTY)
    return a


def call_grid_geometry(a: dict[str, Any]) -> Any:
    geo = make_geometry(a)
    return {
        "fields": (geo.size_x, geo.size_y, geo.resolution, geo.origin_x, geo.origin_y),
        "cell": geo.world_to_cell(a["wx"], a["wy"]),
        "centre": geo.cell_centre(a["cx"], a["cy"]),
        "in_bounds": geo.in_bounds(a["cx"], a["cy"]),
        "repr": repr(geo),
    }


def garbage_grid_geometry(a: dict[str, Any], r: Any) -> str | None:
    problem = geometry_problem(a)
    if problem:
        return f"GridGeometry accepted an invalid grid ({problem})"
    sx, sy, res, ox, oy = r["fields"]
    inside = 0 <= a["cx"] < sx and 0 <= a["cy"] < sy
    if r["in_bounds"] != inside:
        return f"in_bounds({a['cx']}, {a['cy']}) = {r['in_bounds']} on a {sx} x {sy} grid"
    if inside and not all_finite(r["centre"]):
        return f"cell_centre of an in-grid cell is {r['centre']}"
    if finite(a["wx"], a["wy"]):
        qx, qy = (a["wx"] - ox) / res, (a["wy"] - oy) / res
        if abs(qx) < 2**30 and abs(qy) < 2**30:
            fx, fy = math.floor(qx), math.floor(qy)
            if abs(r["cell"][0] - fx) > 1 or abs(r["cell"][1] - fy) > 1:
                return f"world_to_cell gave {r['cell']}, floor gives ({fx}, {fy})"
    return None


# ----------------------------------------------------------------------------- ray traversal
def gen_bresenham(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    mode = g.pick(("small", "small", "small", "offset", "offset", "extreme"))
    if mode == "small":
        c = [int(v) for v in rng.integers(-60, 61, size=4)]
    elif mode == "offset":  # far from 0, short span: must not overflow
        base = g.pick((2**31 - 1, -(2**31), 2**30, -(2**30)))
        sign = -1 if base > 0 else 1
        c = [base + sign * int(v) for v in rng.integers(0, 40, size=4)]
    else:
        c = [int(g.pick(NASTY_INTS)) for _ in range(4)]
    return dict(zip(("x0", "y0", "x1", "y1"), c, strict=True))


def call_bresenham(a: dict[str, Any]) -> Any:
    return core().bresenham_line(a["x0"], a["y0"], a["x1"], a["y1"])


def garbage_bresenham(a: dict[str, Any], cells: Any) -> str | None:
    cells = np.asarray(cells, dtype=np.int64)
    expected = max(abs(a["x1"] - a["x0"]), abs(a["y1"] - a["y0"])) + 1
    if cells.shape != (expected, 2):
        return f"{cells.shape[0]} cells, expected {expected}"
    if tuple(cells[0]) != (a["x0"], a["y0"]) or tuple(cells[-1]) != (a["x1"], a["y1"]):
        return f"runs {tuple(cells[0])} -> {tuple(cells[-1])}"
    if len(cells) > 1 and np.abs(np.diff(cells, axis=0)).max() > 1:
        return "a step of more than one cell"
    return None


def point_args(g: Gen, geo: dict[str, Any], names: Sequence[str]) -> dict[str, Any]:
    """Coordinates near the grid (inside, around, or hostile)."""
    span = max(
        1.0, min(geo["size_x"], 1000) * (geo["resolution"] if finite(geo["resolution"]) else 1.0)
    )
    ox = geo["origin_x"] if finite(geo["origin_x"]) else 0.0
    return {n: g.f(ox - span, ox + 2 * span, 0.3) for n in names}


def gen_ray_cells(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    a = {"geometry": geometry_args(g, 0.9)}
    a.update(point_args(g, a["geometry"], ("x0", "y0", "x1", "y1")))
    a["include_end"] = g.b()
    return a


def call_ray_cells(a: dict[str, Any]) -> Any:
    return core().ray_cells(
        make_geometry(a["geometry"]), a["x0"], a["y0"], a["x1"], a["y1"], a["include_end"]
    )


def cells_problem(cells: Any, sx: int, sy: int) -> str | None:
    cells = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    if len(cells) == 0:
        return None
    outside = (cells[:, 0] < 0) | (cells[:, 0] >= sx) | (cells[:, 1] < 0) | (cells[:, 1] >= sy)
    if outside.any():
        first = tuple(cells[outside][0])
        return f"{int(outside.sum())} cells outside the {sx} x {sy} grid, e.g. {first}"
    return None


def garbage_ray_cells(a: dict[str, Any], cells: Any) -> str | None:
    geo = a["geometry"]
    why = cells_problem(cells, geo["size_x"], geo["size_y"])
    if why:
        return why
    cells = np.asarray(cells, dtype=np.int64)
    if len(cells) > geo["size_x"] + geo["size_y"] + 1:
        return f"{len(cells)} cells on a {geo['size_x']} x {geo['size_y']} grid"
    if len(cells) > 1 and not (np.abs(np.diff(cells, axis=0)).sum(axis=1) == 1).all():
        return "consecutive cells are not edge neighbours"
    return None


# ----------------------------------------------------------------------------- log-odds grid
def log_odds_config_args(g: Gen) -> dict[str, Any]:
    return {
        "p_hit": g.f(0.55, 0.95, 0.15),
        "p_miss": g.f(0.05, 0.45, 0.15),
        "clamp_min": g.f(-12, -1, 0.15),
        "clamp_max": g.f(1, 12, 0.15),
        "occupied_threshold": g.f(0.5, 3, 0.1),
        "free_threshold": g.f(-3, -0.5, 0.1),
    }


def gen_log_odds_grid(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    geo = geometry_args(g, 0.95)
    ops: list[tuple[Any, ...]] = []
    for _ in range(int(rng.integers(1, 8))):
        op = g.pick(("hit", "miss", "cell", "set", "shift", "decay", "reset"))
        if op in ("hit", "miss", "cell"):
            ops.append(
                (
                    op,
                    g.i(0, geo["size_x"] - 1, nasty=INT32_NASTY),
                    g.i(0, geo["size_y"] - 1, nasty=INT32_NASTY),
                )
            )
        elif op == "set":
            ops.append((op, g.array(grid_shape(geo), -20, 20)))
        elif op == "shift":
            ops.append((op, g.i(-30, 30, 0.3, INT32_NASTY), g.i(-30, 30, 0.3, INT32_NASTY)))
        elif op == "decay":
            ops.append((op, g.f(0, 1)))
        else:
            ops.append((op,))
    return {"geometry": geo, "config": log_odds_config_args(g), "ops": ops}


def call_log_odds_grid(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.LogOddsConfig(), a["config"])
    grid = c.LogOddsGrid(make_geometry(a["geometry"]), config)
    errors = 0
    for op in a["ops"]:
        try:
            if op[0] == "hit":
                grid.add_hit(op[1], op[2])
            elif op[0] == "miss":
                grid.add_miss(op[1], op[2])
            elif op[0] == "cell":
                grid.cell_log_odds(op[1], op[2])
                grid.cell_probability(op[1], op[2])
            elif op[0] == "set":
                grid.set_log_odds(op[1])
            elif op[0] == "shift":
                grid.shift(op[1], op[2])
            elif op[0] == "decay":
                grid.decay(op[1])
            else:
                grid.reset()
        except (ValueError, TypeError, IndexError) as error:
            if not str(error):
                raise
            errors += 1
    return {
        "valid": config.validate(),
        "log_odds": grid.log_odds(),
        "probability": grid.probability(),
        "states": grid.states(),
        "max_abs": grid.max_abs_log_odds(),
        "geometry": grid.geometry,
    }


def garbage_log_odds_grid(a: dict[str, Any], r: Any) -> str | None:
    if r["valid"]:
        return f"LogOddsGrid accepted an invalid config ({r['valid']})"
    cfg = a["config"]
    lo, hi = cfg["clamp_min"] - 1e-3, cfg["clamp_max"] + 1e-3
    shape = (a["geometry"]["size_y"], a["geometry"]["size_x"])
    lod, p, s = r["log_odds"], r["probability"], r["states"]
    if lod.shape != shape or p.shape != shape or s.shape != shape:
        return f"arrays of shape {lod.shape}, grid {shape}"
    if not all_finite(lod) or lod.min() < lo or lod.max() > hi:
        clamps = f"[{cfg['clamp_min']}, {cfg['clamp_max']}]"
        return f"log-odds outside the clamps {clamps}: {lod.min()} .. {lod.max()}"
    if not all_finite(p) or p.min() < 0 or p.max() > 1:
        return "probability outside [0, 1]"
    if not np.isin(s, (-1, 0, 1)).all():
        return "states other than -1, 0, 1"
    if not (math.isfinite(r["max_abs"]) and r["max_abs"] <= max(-lo, hi)):
        return f"max_abs_log_odds {r['max_abs']}"
    if r["geometry"].size_x != shape[1] or not finite(
        r["geometry"].origin_x, r["geometry"].origin_y
    ):
        return f"geometry after the ops: {r['geometry']!r}"
    return None


def gen_log_odds_scalars(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.4)
    return {"p": g.f(0, 1), "l": g.f(-30, 30)}


def call_log_odds_scalars(a: dict[str, Any]) -> Any:
    return core().log_odds_of(a["p"]), core().probability_of(a["l"])


def garbage_log_odds_scalars(a: dict[str, Any], r: Any) -> str | None:
    lod, p = r
    if not math.isnan(a["l"]) and not (0.0 <= p <= 1.0):
        return f"probability_of({a['l']}) = {p}"
    if 0.0 < a["p"] < 1.0 and not math.isfinite(lod):
        return f"log_odds_of({a['p']}) = {lod}"
    return None


# ----------------------------------------------------------------------------- scan integration
def scan_config_args(g: Gen) -> dict[str, Any]:
    return {
        "marking": g.b(),
        "clearing": g.b(),
        "obstacle_min_range": g.f(0, 0.5, 0.1),
        "obstacle_max_range": g.f(1, 10, 0.15),
        "raytrace_min_range": g.f(0, 0.5, 0.1),
        "raytrace_max_range": g.f(1, 12, 0.15),
        "inf_is_valid": g.b(),
        "range_max_is_no_return": g.b(),
    }


def pose_args(g: Gen, span: float = 5.0) -> tuple[float, float, float]:
    return (g.f(-span, span, 0.15), g.f(-span, span, 0.15), g.f(-PI, PI, 0.1))


def gen_scan_common(rng: np.random.Generator) -> tuple[Gen, dict[str, Any]]:
    g = Gen(rng)
    n = int(g.pick((0, 1, 2, 16, 90, 360)))
    return g, {
        "geometry": geometry_args(g, 0.95),
        "config": scan_config_args(g),
        "ranges": g.array((n,), 0, 12, np.float32),
        "angle_min": g.f(-PI, 0, 0.15),
        "angle_increment": g.f(0.001, 2 * PI / max(n, 1), 0.15),
        "range_min": g.f(0, 0.2, 0.15),
        "range_max": g.f(5, 30, 0.15),
    }


def gen_scan_integrate(rng: np.random.Generator) -> dict[str, Any]:
    g, a = gen_scan_common(rng)
    a["pose"] = pose_args(g)
    return a


def gen_scan_integrate_moving(rng: np.random.Generator) -> dict[str, Any]:
    g, a = gen_scan_common(rng)
    a["first"] = pose_args(g)
    a["last"] = pose_args(g)
    return a


def make_integrator(a: dict[str, Any]) -> tuple[Any, Any, str]:
    c = core()
    config = configure(c.ScanIntegratorConfig(), a["config"])
    integrator = c.ScanIntegrator(config)
    return integrator, c.LogOddsGrid(make_geometry(a["geometry"])), config.validate()


def call_scan_integrate(a: dict[str, Any]) -> Any:
    integrator, grid, valid = make_integrator(a)
    stats = integrator.integrate(
        grid,
        a["ranges"],
        a["angle_min"],
        a["angle_increment"],
        a["range_min"],
        a["range_max"],
        a["pose"],
    )
    return {"valid": valid, "stats": stats, "grid": grid}


def call_scan_integrate_moving(a: dict[str, Any]) -> Any:
    integrator, grid, valid = make_integrator(a)
    stats = integrator.integrate_moving(
        grid, a["ranges"], a["angle_min"], a["angle_increment"], a["range_min"], a["range_max"],
        a["first"], a["last"],
    )  # fmt: skip
    return {"valid": valid, "stats": stats, "grid": grid}


def gen_scan_integrate_cloud(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    n = int(g.pick((0, 1, 5, 50, 300)))
    transform = np.eye(4)
    transform[:3, 3] = [g.f(-3, 3, 0.1), g.f(-3, 3, 0.1), g.f(0, 1, 0.1)]
    if g.chance(0.15):
        transform = g.array((4, 4), -2, 2)
    return {
        "geometry": geometry_args(g, 0.95),
        "config": scan_config_args(g),
        "points": g.array((n, 3), -6, 6, np.float32),
        "grid_from_sensor": transform,
        "min_obstacle_height": g.f(-0.5, 0.5, 0.1),
        "max_obstacle_height": g.f(0.5, 3, 0.1),
        "merge_cells": g.b(),
    }


def call_scan_integrate_cloud(a: dict[str, Any]) -> Any:
    integrator, grid, valid = make_integrator(a)
    stats = integrator.integrate_cloud(
        grid, a["points"], a["grid_from_sensor"], a["min_obstacle_height"],
        a["max_obstacle_height"], a["merge_cells"],
    )  # fmt: skip
    return {"valid": valid, "stats": stats, "grid": grid}


def garbage_integration(a: dict[str, Any], r: Any) -> str | None:
    if r["valid"]:
        return f"ScanIntegrator accepted an invalid config ({r['valid']})"
    geo, stats, grid = a["geometry"], r["stats"], r["grid"]
    for name in ("touched", "changed"):
        box = getattr(stats, name)
        if box and not (
            0 <= box[0] <= box[2] < geo["size_x"] and 0 <= box[1] <= box[3] < geo["size_y"]
        ):
            return f"stats.{name} {box} leaves the {geo['size_x']} x {geo['size_y']} grid"
    lod = grid.log_odds()
    if not all_finite(lod) or np.abs(lod).max(initial=0) > 8.0 + 1e-3:
        return f"log-odds outside the default clamps: {lod.min()} .. {lod.max()}"
    if stats.beams_marked > stats.beams or stats.cells_marked > lod.size:
        return f"{stats.beams_marked} beams marked of {stats.beams}, {stats.cells_marked} cells"
    return None


# ----------------------------------------------------------------------------- SE(2)
def gen_se2(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.3)
    return {
        "op": g.pick(("compose", "inverse", "interpolate", "normalize", "shortest", "apply")),
        "a": pose_args(g, 100),
        "b": pose_args(g, 100),
        "t": (g.f(0, 10), g.f(0, 10), g.f(-5, 15)),
        "angle": g.f(-50, 50, 0.4),
        "angle2": g.f(-50, 50, 0.4),
        "points": g.array((int(rng.integers(0, 20)), 2), -100, 100),
    }


def call_se2(a: dict[str, Any]) -> Any:
    c = core()
    pa, pb = c.Pose2D(*a["a"]), c.Pose2D(*a["b"])
    op = a["op"]
    if op == "compose":
        return c.compose(pa, pb).as_tuple()
    if op == "inverse":
        return c.inverse(pa).as_tuple()
    if op == "interpolate":
        return c.interpolate(pa, a["t"][0], pb, a["t"][1], a["t"][2]).as_tuple()
    if op == "normalize":
        return c.normalize_angle(a["angle"])
    if op == "shortest":
        return c.shortest_angular_distance(a["angle"], a["angle2"])
    return c.apply(pa, a["points"])


def moderate(*values: Any) -> bool:
    """Finite and small enough that products and sums stay finite."""
    try:
        v = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        return False
    return bool(np.all(np.isfinite(v)) and np.all(np.abs(v) < 1e100))


def garbage_se2(a: dict[str, Any], r: Any) -> str | None:
    op = a["op"]
    if op in ("normalize", "shortest"):
        inputs = (a["angle"],) if op == "normalize" else (a["angle"], a["angle2"])
        # |angles| <= 1e100: the difference of two cannot overflow to Inf.
        if moderate(*inputs) and not (-PI - 1e-12 <= r <= PI + 1e-12):
            return f"{op} of {inputs} = {r}, not in [-pi, pi]"
        return None
    if op == "interpolate" and a["t"][0] == a["t"][1] and moderate(*a["a"]):
        if not np.allclose(r, a["a"]):
            return f"interpolate with t_a == t_b gave {r}, not a"
    if op == "apply":
        points = np.asarray(r)
        if moderate(*a["a"]) and isinstance(a["points"], np.ndarray) and moderate(a["points"]):
            if points.shape != np.shape(a["points"]) or not all_finite(points):
                return "apply of finite points is not finite (or has another shape)"
        return None
    inputs = (*a["a"], *a["b"], *a["t"]) if op != "inverse" else a["a"]
    if moderate(*inputs) and not all_finite(r):
        return f"{op} of finite poses gave {r}"
    return None


# ----------------------------------------------------------------------------- static map
def occupancy_array(g: Gen, shape: tuple[int, int]) -> Any:
    """int8 occupancy of `shape`, or (hostile) a wrong one: 1-D, 3-D, empty, floats."""
    good = g.rng.integers(-128, 128, size=shape).astype(np.int8)
    if not g.chance(g.hostile):
        return good
    kind = g.pick(("1d", "3d", "empty", "float", "list"))
    if kind == "1d":
        return good.reshape(-1)
    if kind == "3d":
        return good.reshape((*shape, 1))
    if kind == "empty":
        return np.zeros((0, shape[1]), dtype=np.int8)
    if kind == "float":
        return g.floats(shape, -200, 200)
    return good.tolist()


def gen_static_map(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    shape = (g.i(1, 40, 0.05, nasty=(0, 1)), g.i(1, 40, 0.05, nasty=(0, 1)))
    return {
        "config": {
            "track_unknown_space": g.b(),
            "use_maximum": g.b(),
            "lethal_cost_threshold": g.i(-5, 120, nasty=INT32_NASTY),
            "unknown_cost_value": g.i(-2, 255, nasty=INT32_NASTY),
            "trinary_costmap": g.b(),
            "max_cells": g.i(1, 4000, 0.1, nasty=(0, 1, 2**31, 2**63)),
        },
        "map": occupancy_array(g, shape),
        "resolution": g.f(0.01, 1.0),
        "origin": (g.f(-100, 100), g.f(-100, 100)),
        "update_at": (g.i(-3, 45, nasty=NASTY_INTS), g.i(-3, 45, nasty=NASTY_INTS)),
        "update": occupancy_array(g, (g.i(1, 12, 0.05, nasty=(0,)), g.i(1, 12, 0.05, nasty=(0,)))),
    }


def call_static_map(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.StaticMapConfig(), a["config"])
    values = c.static_map_values(a["map"], config)
    m = c.StaticMap(config)
    outcome = {"values": values, "set": None, "update": None}
    try:
        m.set_map(a["map"], a["resolution"], *a["origin"])
        outcome["set"] = "ok"
    except (ValueError, TypeError) as error:
        outcome["set"] = str(error)
    before = m.costs() if m.has_map else None
    try:
        m.apply_update(*a["update_at"], a["update"])
        outcome["update"] = "ok"
    except (ValueError, TypeError, OverflowError) as error:
        outcome["update"] = str(error)
    outcome["before"], outcome["after"], outcome["has_map"] = before, m.costs(), m.has_map
    return outcome


def garbage_static_map(a: dict[str, Any], r: Any) -> str | None:
    values = r["values"]
    if values.dtype != np.uint8 or values.size != np.asarray(a["map"], dtype=object).size:
        return f"static_map_values gave {values.dtype} of {values.size} values"
    if r["set"] != "ok" and r["has_map"]:
        return f"a refused map ({r['set']}) left a map"
    if (
        r["update"] != "ok"
        and r["before"] is not None
        and not np.array_equal(r["before"], r["after"])
    ):
        return f"a refused update ({r['update']}) changed the map"
    if r["set"] == "ok" and r["after"].shape != np.shape(a["map"]):
        return f"costs of shape {r['after'].shape} for a map of {np.shape(a['map'])}"
    return None


# ----------------------------------------------------------------------------- costs, inflation
def call_occupancy_table(a: dict[str, Any]) -> Any:
    return core().occupancy_table()


def garbage_occupancy_table(a: dict[str, Any], table: Any) -> str | None:
    if table.shape != (256,) or table.min() < -1 or table.max() > 100:
        return f"table shape {table.shape}, values {table.min()} .. {table.max()}"
    return None


def inflation_config_args(g: Gen) -> dict[str, Any]:
    return {
        "inflation_radius": g.f(0, 1.5, 0.2),
        "cost_scaling_factor": g.f(0, 20, 0.15),
        "inscribed_radius": g.f(0, 0.5, 0.15),
        "inflate_unknown": g.b(),
    }


def gen_inflation_cost(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    return {"distance": g.f(0, 2), "config": inflation_config_args(g)}


def call_inflation_cost(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.InflationConfig(), a["config"])
    return c.inflation_cost(a["distance"], config), config.validate()


def garbage_inflation_cost(a: dict[str, Any], r: Any) -> str | None:
    cost, valid = r
    d, cfg = a["distance"], a["config"]
    if valid or not (math.isfinite(d) and d >= 0):
        return None  # no promise for invalid settings (inflate() is where they must be refused)

    # costmap_2d: nothing beyond the inflation radius, even inside a larger inscribed radius.
    # Near either radius the C++ allows a rounding tolerance: no claim there.
    def margin(v: float) -> float:
        return abs(v) * 1e-6 + 1e-9

    r, ins = cfg["inflation_radius"], cfg["inscribed_radius"]
    if d == 0:
        return None if cost == 254 else f"cost {cost} at distance 0"
    if d > r + margin(r):
        return None if cost == 0 else f"cost {cost} beyond the inflation radius"
    if d < r - margin(r) and d < ins - margin(ins):
        return None if cost == 253 else f"cost {cost} inside the inscribed radius"
    if ins + margin(ins) < d < r - margin(r) and cost > 252:
        return f"cost {cost} outside the inscribed radius"
    return None


def gen_inflate(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    h, w = int(rng.integers(1, 50)), int(rng.integers(1, 50))
    costs = rng.choice([0, 0, 0, 0, 0, 254, 255, 100], size=(h, w)).astype(np.uint8)
    if g.chance(0.15):
        costs = g.array((h, w), 0, 255, np.uint8)
    return {
        "costs": costs,
        "resolution": g.f(0.02, 0.2, 0.2),
        "config": inflation_config_args(g),
    }


def call_inflate(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.InflationConfig(), a["config"])
    return c.inflate(a["costs"], a["resolution"], config), config.validate()


def garbage_inflate(a: dict[str, Any], r: Any) -> str | None:
    out, valid = r
    if valid:
        return f"inflate accepted an invalid config ({valid})"
    res = a["resolution"]
    if not (math.isfinite(res) and res > 0):
        return f"inflate accepted resolution {res}"
    costs = a["costs"]
    if not isinstance(costs, np.ndarray) or costs.dtype != np.uint8 or costs.ndim != 2:
        return None  # converted by pybind11: compare only the shape of a clean input
    if out.shape != costs.shape:
        return f"output shape {out.shape} for input {costs.shape}"
    known = costs != 255
    if (out[costs == 254] != 254).any() or (out[known] < costs[known]).any():
        return "inflation lowered a cost or removed a lethal cell"
    return None


# ----------------------------------------------------------------------------- footprints
def polygon_args(g: Gen) -> list[tuple[float, float]]:
    n = int(g.pick((0, 1, 2, 3, 4, 4, 5, 8)))
    if g.chance(0.7):
        return [(g.f(-1, 1, 0.05), g.f(-1, 1, 0.05)) for _ in range(n)]
    return [(g.f(-1, 1, 0.5), g.f(-1, 1, 0.5)) for _ in range(n)]


def gen_footprint_radii(rng: np.random.Generator) -> dict[str, Any]:
    return {"points": polygon_args(Gen(rng))}


def call_footprint_radii(a: dict[str, Any]) -> Any:
    return core().footprint_radii(a["points"])


def garbage_footprint_radii(a: dict[str, Any], r: Any) -> str | None:
    points = a["points"]
    if len(points) < 3 or not finite(*[v for p in points for v in p]):
        return f"accepted an invalid footprint {points}"
    inscribed, circumscribed = r
    if not finite(inscribed, circumscribed) or inscribed < 0 or inscribed > circumscribed + 1e-9:
        return f"radii {r}"
    return None


def gen_footprint_cells(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    geo = geometry_args(g, 0.95)
    return {"points": polygon_args(g), "pose": pose_args(g, 5), "geometry": geo}


def call_footprint_cells(a: dict[str, Any]) -> Any:
    return core().footprint_cells(a["points"], a["pose"], make_geometry(a["geometry"]))


def garbage_footprint_cells(a: dict[str, Any], mask: Any) -> str | None:
    shape = (a["geometry"]["size_y"], a["geometry"]["size_x"])
    if mask.shape != shape or mask.dtype != bool:
        return f"mask {mask.shape} {mask.dtype} for a grid {shape}"
    return None


# ----------------------------------------------------------------------------- boxes
def box_args(g: Gen) -> tuple[float, float, float, float]:
    x, y = g.f(0, 600), g.f(0, 400)
    return (x, y, x + g.f(1, 200), y + g.f(1, 200))


def gen_iou(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    return {"a": box_args(g), "b": box_args(g)}


def call_iou(a: dict[str, Any]) -> Any:
    return core().iou(a["a"], a["b"])


def garbage_iou(a: dict[str, Any], r: Any) -> str | None:
    if math.isnan(r) and not finite(*a["a"], *a["b"]):
        return None
    if not (0.0 <= r <= 1.0):
        return f"iou = {r}"
    return None


def gen_nms(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    n = int(g.pick((0, 1, 3, 10, 40)))
    boxes = np.array([box_args(g) for _ in range(n)]).reshape(n, 4)
    m = n if g.chance(0.8) else int(g.pick((0, max(n - 1, 0), n + 3)))
    return {
        "boxes": g.array((n, 4), 0, 1, np.float64) if g.chance(0.1) else boxes,
        "scores": g.floats((m,), 0, 1),
        "iou_threshold": g.f(0, 1, 0.2),
        "class_ids": None
        if g.b()
        else [int(v) for v in rng.integers(-1, 3, size=m if g.b() else n)],
    }


def call_nms(a: dict[str, Any]) -> Any:
    return core().nms(a["boxes"], a["scores"], a["iou_threshold"], a["class_ids"])


def garbage_nms(a: dict[str, Any], kept: Any) -> str | None:
    n = len(a["boxes"]) if hasattr(a["boxes"], "__len__") else -1
    if np.size(a["scores"]) != n:
        return f"accepted {np.size(a['scores'])} scores for {n} boxes (reads past the scores)"
    if a["class_ids"] is not None and len(a["class_ids"]) != n:
        return f"accepted {len(a['class_ids'])} class ids for {n} boxes"
    kept = np.asarray(kept)
    if kept.size and (kept.min() < 0 or kept.max() >= n or len(set(kept.tolist())) != kept.size):
        return f"kept indices {kept.tolist()} for {n} boxes"
    return None


def gen_mask_iou(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    shape = (int(rng.integers(0, 30)), int(rng.integers(0, 30)))
    a = (rng.random(shape) < 0.3).astype(np.uint8)
    b = (rng.random(shape) < 0.3).astype(np.uint8)
    if g.chance(0.25):
        b = g.array(shape, 0, 2, np.uint8)
    return {"a": a, "b": b}


def call_mask_iou(a: dict[str, Any]) -> Any:
    return core().mask_iou(a["a"], a["b"])


def garbage_mask_iou(a: dict[str, Any], r: Any) -> str | None:
    return None if 0.0 <= r <= 1.0 else f"mask_iou = {r}"


# ----------------------------------------------------------------------------- seam health
def gen_expected_smear(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.35)
    limits = {
        name: g.f(lo, hi, 0.15)
        for name, lo, hi in (
            ("reference_range_m", 0, 30), ("max_transform_age_s", 0, 1),
            ("max_smear_m", 0, 1), ("max_map_odom_age_s", 0, 10),
        )
    }  # fmt: skip
    return {
        "range_m": g.f(0, 30), "yaw_rate_rps": g.f(-3, 3), "age_s": g.f(0, 0.3), "limits": limits,
    }  # fmt: skip


def call_expected_smear(a: dict[str, Any]) -> Any:
    c = core()
    # SeamLimits is a plain holder of the handoff's warning limits: whatever is stored (NaN,
    # Inf, negative) must read back unchanged; the nodelet validates them (acceptValid).
    limits = configure(c.SeamLimits(), a["limits"])
    read_back = {name: getattr(limits, name) for name in a["limits"]}
    return c.expected_smear(a["range_m"], a["yaw_rate_rps"], a["age_s"]), read_back


def garbage_expected_smear(a: dict[str, Any], result: Any) -> str | None:
    r, read_back = result
    for name, value in a["limits"].items():
        stored = read_back[name]
        if not (stored == value or (math.isnan(stored) and math.isnan(value))):
            return f"SeamLimits.{name} stored {value}, read back {stored}"
    rng_m, rate, age = a["range_m"], a["yaw_rate_rps"], a["age_s"]
    if moderate(rng_m, rate, age) and abs(rate * age) < 1.5 and rng_m >= 0 and age >= 0:
        if not (math.isfinite(r) and r >= 0):
            return f"smear {r}"
    return None


def gen_correction_monitor(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    config = {
        name: g.f(lo, hi, 0.15)
        for name, lo, hi in (
            ("window_s", 1, 200), ("reset_drop_m", 0.01, 0.2), ("max_correction_m", 0.5, 5),
            ("zero_epsilon_m", 1e-4, 1e-2), ("min_travel_m", 1, 50), ("ramp_m", 0.1, 2),
        )
    }  # fmt: skip
    n = int(g.pick((0, 1, 10, 100)))
    t = np.cumsum(rng.uniform(0, 2, size=n))
    return {
        "config": config,
        "samples": [
            (g.f(float(ti), float(ti), 0.05), g.f(0, 3, 0.1), g.f(0, 100, 0.1)) for ti in t
        ],
        "many": (g.array((n,), 0, 100), g.array((n,), 0, 3), g.array((n,), 0, 100)),
    }


def call_correction_monitor(a: dict[str, Any]) -> Any:
    c = core()
    monitor = c.CorrectionMonitor(configure(c.CorrectionMonitorConfig(), a["config"]))
    for sample in a["samples"]:
        monitor.add(*sample)
    monitor.add_many(*a["many"])
    return (
        monitor.findings(),
        monitor.resets,
        monitor.never_resets(),
        monitor.stuck_at_zero(),
        monitor.too_large(),
    )


def garbage_correction_monitor(a: dict[str, Any], r: Any) -> str | None:
    findings = r[0]
    if not all(isinstance(f, str) and f for f in findings):
        return f"findings {findings!r}"
    return None


# ----------------------------------------------------------------------------- prediction
def prediction_config_args(g: Gen) -> dict[str, Any]:
    return {
        "prediction_horizon_s": g.f(0, 3, 0.15),
        "uncertainty_sigmas": g.f(0, 3, 0.15),
        "max_uncertainty_m": g.f(0, 2, 0.15),
        "min_object_size_m": g.f(0, 0.3, 0.15),
        "max_object_size_m": g.f(1, 6, 0.15),
        "max_speed_mps": g.f(1, 20, 0.15),
    }


def track_args(g: Gen) -> dict[str, Any]:
    return {
        "position": g.array((2,), -5, 5),
        "velocity": g.array((2,), -2, 2),
        "position_covariance": np.diag([g.f(0, 0.1, 0.15), g.f(0, 0.1, 0.15)]),
        "velocity_covariance": np.diag([g.f(0, 0.5, 0.15), g.f(0, 0.5, 0.15)]),
        "size_x": g.f(0.1, 1.5),
        "size_y": g.f(0.1, 1.5),
        "box_yaw": g.f(-PI, PI),
    }


def make_track(a: dict[str, Any]) -> Any:
    t = a["track"]
    return core().PlanarTrack(
        t["position"], t["velocity"], t["position_covariance"], t["velocity_covariance"],
        t["size_x"], t["size_y"], t["box_yaw"],
    )  # fmt: skip


def gen_prediction(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.2)
    return {
        "op": g.pick(("uncertainty", "swept", "predicted", "recent")),
        "track": track_args(g),
        "config": prediction_config_args(g),
        "dt": g.f(0, 2),
        "lookback": g.f(0, 1),
        "margin": g.f(0, 0.3),
        "max_size": g.f(1, 5),
        "geometry": geometry_args(g, 0.95),
    }


def call_prediction(a: dict[str, Any]) -> Any:
    c = core()
    track = make_track(a)
    config = configure(c.PredictionConfig(), a["config"])
    valid = "; ".join(why for why in (track.validate(), config.validate()) if why)
    op = a["op"]
    if op == "uncertainty":
        return valid, c.uncertainty_radius(track, a["dt"], config)
    if op == "swept":
        return valid, c.swept_polygon(track, a["dt"], config)
    geo = make_geometry(a["geometry"])
    if op == "predicted":
        return valid, c.predicted_cells(track, a["dt"], config, geo)
    return valid, c.recent_cells(track, a["lookback"], a["dt"], a["margin"], a["max_size"], geo)


def garbage_prediction(a: dict[str, Any], r: Any) -> str | None:
    invalid, out = r
    note = f" (inputs invalid: {invalid}; not refused)" if invalid else ""
    op = a["op"]
    if op == "uncertainty":
        cap = a["config"]["max_uncertainty_m"]
        if not (math.isfinite(out) and out >= 0):
            return f"uncertainty radius {out}{note}"
        if not invalid and out > cap + 1e-9:
            return f"uncertainty radius {out} above max_uncertainty_m {cap}"
        return None
    if op == "swept":
        if not all_finite(out):
            return f"swept polygon has non-finite vertices{note}"
        return None
    geo = a["geometry"]
    why = cells_problem(out, geo["size_x"], geo["size_y"])
    if why:
        return why
    if len(out) and len({tuple(c) for c in np.asarray(out).tolist()}) != len(out):
        return "a cell listed twice"
    return None


def gen_chi_square(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.35)
    return {"dof": g.i(1, 6, nasty=INT32_NASTY), "confidence": g.f(0.5, 0.99999)}


def call_chi_square(a: dict[str, Any]) -> Any:
    return core().chi_square_quantile(a["dof"], a["confidence"])


def garbage_chi_square(a: dict[str, Any], q: Any) -> str | None:
    if not (a["dof"] >= 1 and 0 < a["confidence"] < 1):
        return f"accepted dof {a['dof']}, confidence {a['confidence']} (gave {q})"
    if not (math.isfinite(q) and q >= 0):
        return f"quantile {q}"
    return None


def gen_assignment(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    rows, cols = int(g.pick((0, 1, 2, 5, 12, 40))), int(g.pick((0, 1, 3, 5, 12, 40)))
    cost = g.floats((rows, cols), 0, 10, 0.15)
    if g.chance(0.3):
        cost[rng.random((rows, cols)) < 0.3] = INF
    return {"cost": cost if g.chance(0.9) else g.array((rows, cols), 0, 10)}


def call_assignment(a: dict[str, Any]) -> Any:
    return core().solve_assignment(a["cost"])


def garbage_assignment(a: dict[str, Any], out: Any) -> str | None:
    cost = np.asarray(a["cost"])
    if cost.ndim != 2 or cost.dtype.kind not in "fiub":
        return None
    rows, cols = cost.shape
    out = list(out)
    if len(out) != rows:
        return f"{len(out)} answers for {rows} rows"
    taken = [c for c in out if c != -1]
    if any(not (-1 <= c < cols) for c in out) or len(set(taken)) != len(taken):
        return f"assignment {out} on {rows} x {cols}"
    for row, col in enumerate(out):
        if col != -1 and not (np.isfinite(cost[row, col]) and cost[row, col] < INF):
            return f"row {row} assigned to forbidden column {col} (cost {cost[row, col]})"
    return None


# ----------------------------------------------------------------------------- tracker
def gen_tracker(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.15)
    image = g.chance(0.3)
    config = {
        "gate_confidence": g.f(0.9, 0.9999),
        "duplicate_confidence": g.f(0.5, 0.95),
        "reid_confidence": g.f(0.99, 0.999999),
        "min_iou": g.f(0.1, 0.5),
        "accel_psd": g.f(0.1, 2),
        "measurement_std": g.f(0.05, 0.5),
        "initial_velocity_std": g.f(0.5, 2),
        "min_hits": g.i(1, 4, nasty=INT32_NASTY),
        "confirm_at_start": g.b(),
        "maximize_matches": g.b(),
        "start_confirm_score": g.f(0.4, 0.8),
        "max_age_s": g.f(0.5, 3),
        "high_score": g.f(0.4, 0.7),
        "low_score": g.f(0.05, 0.3),
        "second_pass": g.b(),
        "class_aware": g.b(),
    }
    steps = []
    stamp = g.f(0, 100, 0.05)
    objects = rng.uniform(-5, 5, size=(4, 2)) if not image else rng.uniform(50, 500, size=(4, 2))
    for _ in range(int(rng.integers(1, 8))):
        stamp = stamp + (g.f(0.05, 0.2, 0.1) if g.chance(0.95) else -1.0)
        n = int(g.pick((0, 1, 2, 3, 4)))
        if image:
            centres = objects[:n] + rng.normal(0, 2, size=(n, 2))
            size = rng.uniform(20, 80, size=(n, 2))
            positions = np.hstack([centres - size / 2, centres + size / 2])
        else:
            positions = objects[:n] + rng.normal(0, 0.05, size=(n, 2))
        cols = 4 if image else 2
        if g.chance(0.3):
            mask = rng.random(positions.shape) < 0.3
            positions = np.where(
                mask,
                np.array(NASTY_FLOATS)[rng.integers(len(NASTY_FLOATS), size=positions.shape)],
                positions,
            )
        if g.chance(0.1):
            positions = g.array((n, cols), 0, 100)
        step: dict[str, Any] = {"stamp": stamp, "positions": positions}
        if g.b():
            step["scores"] = g.floats((n if g.chance(0.9) else n + 1,), 0, 1, 0.1)
        if g.b():
            step["class_ids"] = rng.integers(-1, 3, size=n if g.chance(0.9) else n + 1).astype(
                np.int32
            )
        if g.chance(0.4):
            cov = np.tile(np.eye(2) * 0.01, (n, 1, 1))
            if g.chance(0.5):
                cov = cov * g.f(-1, 1, 0.8)
            step["covariances"] = cov if g.chance(0.9) else g.array((n, 2, 2), -1, 1)
        if g.chance(0.3):
            step["truth_ids"] = np.arange(n, dtype=np.int32)
        steps.append(step)
    return {"image": image, "config": config, "steps": steps}


def call_tracker(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.TrackerConfig(), a["config"])
    if a["image"]:
        config.mode = c.TrackerConfig.Mode.IMAGE
    tracker = c.Tracker(config)
    last_n = None  # detections of the last step the tracker took
    for step in a["steps"]:
        kwargs = {k: v for k, v in step.items() if k not in ("stamp", "positions")}
        try:
            tracker.step(step["stamp"], step["positions"], **kwargs)
            last_n = len(step["positions"])
        except (ValueError, TypeError) as error:
            if not str(error):
                raise
    return {
        "valid": config.validate(),
        "tracks": tracker.tracks(),
        "assignment": tracker.last_assignment(),
        "last_n": last_n,
    }


def garbage_tracker(a: dict[str, Any], r: Any) -> str | None:
    if r["valid"]:
        return f"Tracker accepted an invalid config ({r['valid']})"
    t = r["tracks"]
    for key in ("position", "velocity", "position_cov", "velocity_cov", "size"):
        if not all_finite(t[key]):
            return f"a track with non-finite {key}"
    if len(t["size"]) and t["size"].min() < 0:
        return f"a track with negative size {t['size'].min()}"
    if len(t["position_cov"]):
        diag = np.concatenate(
            [t["position_cov"][:, [0, 1], [0, 1]], t["velocity_cov"][:, [0, 1], [0, 1]]]
        )
        if diag.min() < 0:
            return f"a track covariance with a negative variance {diag.min()}"
    if r["last_n"] is not None and len(r["assignment"]) not in (0, r["last_n"]):
        return f"last_assignment has {len(r['assignment'])} entries for {r['last_n']} detections"
    return None


# ----------------------------------------------------------------------------- TSDF and OctoMap
def camera_args(g: Gen) -> dict[str, Any]:
    w, h = int(g.pick((1, 4, 16, 32, 48))), int(g.pick((1, 3, 12, 24, 36)))
    return {
        "fx": g.f(20, 60, 0.1),
        "fy": g.f(20, 60, 0.1),
        "cx": g.f(0, w, 0.15) if g.chance(0.9) else 1e7,
        "cy": g.f(0, h, 0.1),
        "width": g.i(w, w, 0.08, INT32_NASTY),
        "height": g.i(h, h, 0.08, INT32_NASTY),
        "shape": (h, w),
    }


def make_camera(cam: dict[str, Any]) -> Any:
    return core().PinholeCamera(
        cam["fx"], cam["fy"], cam["cx"], cam["cy"], cam["width"], cam["height"]
    )


def pose_matrix(g: Gen) -> Any:
    m = np.eye(4)
    yaw = g.f(-PI, PI, 0.05)
    m[:2, :2] = (
        [[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]]
        if finite(yaw)
        else np.eye(2)
    )
    m[:3, 3] = [g.f(-1, 1, 0.1), g.f(-1, 1, 0.1), g.f(0, 1, 0.1)]
    if g.chance(0.1):
        return g.array((4, 4), -1, 1)
    return m


def depth_args(g: Gen, shape: tuple[int, int]) -> Any:
    depth = f32_array(g.floats(shape, 0.3, 4, 0.1))
    if g.chance(0.1):
        depth[:] = INF  # a frame without a single return
    kind = g.pick(("f32", "f32", "f32", "f64", "u16", "hostile"))
    if kind == "f64":
        return depth.astype(np.float64)
    if kind == "u16":
        return (np.nan_to_num(depth, nan=0, posinf=0, neginf=0).clip(0, 60) * 1000).astype(
            np.uint16
        )
    if kind == "hostile":
        return g.array(shape, 0.3, 4, g.pick((np.float32, np.int32, np.int8, np.float16)))
    return depth


def tsdf_config_args(g: Gen) -> dict[str, Any]:
    return {
        "voxel_size_m": g.f(0.05, 0.2, 0.12),
        "truncation_voxels": g.f(2, 5, 0.1),
        "max_weight": g.f(10, 100, 0.1),
        "behind_surface_dropoff": g.b(),
        "behind_surface_dropoff_start_voxels": g.f(0, 6, 0.1),
        "confirm_depth_voxels": g.f(0, 5, 0.1),
        "confirm_depth_max_m": g.f(0, 0.2, 0.1),
        "unconfirmed_update_weight": g.f(0.01, 1, 0.1),
        "far_free_guess_weight": g.f(0.01, 1, 0.1),
        "incidence_window_radius_px": g.i(0, 8, 0.1),
        "edge_guard_rad": g.f(0, 0.01, 0.1),
        "edge_guard_near_side_only": g.b(),
        "edge_guard_grazing_voxels": g.f(1, 4, 0.1),
        "edge_guard_rim_scale": g.f(0.2, 3, 0.1),
        "grazing_reach_voxels": g.f(0, 3, 0.1),
        "grazing_reach_max_voxels": g.f(1, 32, 0.1),
        "edge_guard_rule": g.pick(("RIM_DISTANCE", "FIXED_RADIUS")),
        "interpolate_depth": g.b(),
        "carve_free_space": g.chance(0.3),
        "min_depth_m": g.f(0.05, 0.3, 0.1),
        "max_depth_m": g.f(3, 10, 0.1),
        "min_weight": g.f(0, 0.01, 0.1),
        "max_blocks": g.i(2000, 20000, 0.1, (0, 1, 9, 2**31 - 1, 2**63, 2**64 - 1)),
        "max_block_distance_m": g.f(0, 8, 0.1) if g.b() else 0.0,
        "weighting": g.pick(("CONSTANT", "INVERSE_SQUARE_DEPTH")),
    }


def make_tsdf_config(fields: dict[str, Any]) -> Any:
    c = core()
    weighting = getattr(c.TsdfWeighting, fields["weighting"])
    rule = getattr(c.TsdfEdgeGuardRule, fields.get("edge_guard_rule", "RIM_DISTANCE"))
    return configure(c.TsdfConfig(), {**fields, "weighting": weighting, "edge_guard_rule": rule})


def sample_points(g: Gen) -> Any:
    pts = g.floats((int(g.pick((0, 1, 8))), 3), -2, 4, 0.0)
    far = np.array(
        [[NAN, 0, 0], [0, NAN, 1], [INF, 0, 0], [1e18, 1e18, 1e18], [-1e300, 0, 0], [1e9, 0, 0]]
    )
    return np.vstack([pts, far[: int(g.rng.integers(0, len(far) + 1))]])


def gen_tsdf(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.2)
    ops: list[tuple[Any, ...]] = []
    for _ in range(int(rng.integers(1, 6))):
        op = g.pick(
            ("depth", "depth", "points", "set_config", "slice", "mesh", "health", "write_ply")
        )
        if op == "depth":
            cam = camera_args(g)
            ops.append((op, depth_args(g, cam["shape"]), cam, pose_matrix(g)))
        elif op == "points":
            ops.append(
                (op, g.array((int(g.pick((0, 1, 20, 100))), 3), -2, 4), g.array((3,), -1, 1))
            )
        elif op == "set_config":
            ops.append((op, tsdf_config_args(g)))
        elif op == "slice":
            ops.append((op, geometry_args(g, 0.9), g.f(0, 0.5), g.f(0.5, 2), g.f(-1, 0.2)))
        elif op == "write_ply":
            ops.append((op, g.pick(("mesh.ply", "a\0b.ply", "", "dir/x.ply", "x" * 300))))
        else:
            ops.append((op,))
    return {"config": tsdf_config_args(g), "ops": ops, "sample": sample_points(g)}


def call_tsdf(a: dict[str, Any]) -> Any:
    c = core()
    config = make_tsdf_config(a["config"])
    tsdf = c.Tsdf(config)
    cap = config.max_blocks
    problems: list[str] = []
    for op in a["ops"]:
        try:
            if op[0] == "depth":
                tsdf.integrate_depth(op[1], make_camera(op[2]), op[3])
            elif op[0] == "points":
                tsdf.integrate_points(op[1], op[2])
            elif op[0] == "set_config":
                same_lattice = {
                    "voxel_size_m": config.voxel_size_m,
                    "truncation_voxels": config.truncation_voxels,
                }
                new = make_tsdf_config({**op[1], **same_lattice})
                tsdf.set_config(new)
                cap = new.max_blocks
                continue
            elif op[0] == "slice":
                out = tsdf.slice(make_geometry(op[1]), op[2], op[3], op[4])
                if (
                    out.shape != (op[1]["size_y"], op[1]["size_x"])
                    or not np.isin(out, (-1, 0, 1)).all()
                ):
                    problems.append(f"slice of shape {out.shape} / values {np.unique(out)}")
            elif op[0] == "mesh":
                tsdf.update_mesh()
            elif op[0] == "health":
                tsdf.health()
            elif op[0] == "write_ply":
                with tempfile.TemporaryDirectory() as d:
                    tsdf.write_ply(os.path.join(d, op[1]))
        except (ValueError, TypeError, IndexError, RuntimeError) as error:
            if not str(error):
                raise
        if tsdf.block_count > cap:
            problems.append(f"{tsdf.block_count} blocks with max_blocks {cap} after {op[0]}")
    tsdf.update_mesh()
    distance, weight = tsdf.sample(a["sample"])
    return {
        "valid": config.validate(),
        "problems": problems,
        "distance": distance,
        "weight": weight,
        "mesh": tsdf.mesh(),
        "health": tsdf.health(),
    }


def garbage_tsdf(a: dict[str, Any], r: Any) -> str | None:
    if r["valid"]:
        return f"Tsdf accepted an invalid config ({r['valid']})"
    if r["problems"]:
        return r["problems"][0]
    pts = np.asarray(a["sample"])
    bad = ~np.isfinite(pts).all(axis=1) | (np.abs(pts).max(axis=1, initial=0) > 1e6)
    bad_rows = np.flatnonzero(bad & (np.isfinite(r["distance"]) | (r["weight"] > 0)))
    if bad_rows.size:
        row = bad_rows[0]
        value = f"distance {r['distance'][row]}, weight {r['weight'][row]}"
        return f"sample at {pts[row].tolist()} gives {value} (expected NaN, 0)"
    mesh = r["mesh"]
    if not all_finite(mesh["vertices"]) or (
        mesh["triangles"].size and mesh["triangles"].max() >= len(mesh["vertices"])
    ):
        return "mesh with non-finite vertices or triangle indices past the vertices"
    h = r["health"]
    for key in ("low_gradient_fraction",):
        if math.isfinite(h[key]) and not (0 <= h[key] <= 1):
            return f"health {key} = {h[key]}"
    return None


def gen_esdf(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.2)
    ops: list[tuple[Any, ...]] = []
    for _ in range(int(rng.integers(1, 7))):
        op = g.pick(("depth", "points", "update", "update", "recompute", "set_esdf", "clear"))
        if op == "depth":
            cam = camera_args(g)
            ops.append((op, depth_args(g, cam["shape"]), cam, pose_matrix(g)))
        elif op == "points":
            ops.append((op, g.array((int(g.pick((0, 1, 50))), 3), -2, 4), g.array((3,), -1, 1)))
        elif op == "set_esdf":
            ops.append((op, g.f(0.1, 2.0, 0.3)))
        else:
            ops.append((op,))
    return {
        "config": tsdf_config_args(g),
        "max_distance_m": g.f(0.1, 2.0, 0.3),
        "ops": ops,
        "query": sample_points(g),
        "band": (g.f(-1, 1), g.f(0.5, 3), g.f(0.05, 3)),  # min_z_m, max_z_m, max_distance_m
        # Tsdf.slice_window: centre x, y (m), side (m), max_cells.
        "window": (g.f(-2, 4), g.f(-2, 4), g.f(0, 4), g.i(1, 3000)),
        # esdf_band_slice's max_computed_columns over that window (0: no bound).
        "padding_bound": g.i(0, 1500),
    }


def call_esdf(a: dict[str, Any]) -> Any:
    c = core()
    config = make_tsdf_config(a["config"])
    if config.validate():
        return {"skipped": True}  # the Tsdf target covers invalid map configs
    tsdf = c.Tsdf(config)
    max_distance: list[float] = []  # the ESDF's accepted caps, last one current
    problems: list[str] = []

    def set_esdf(value: float) -> None:
        e = c.EsdfConfig()
        e.max_distance_m = value
        valid = e.validate(config.voxel_size_m) == ""
        try:
            tsdf.set_esdf_config(e)
            max_distance.append(value)
            if not valid:
                problems.append(f"set_esdf_config accepted max_distance_m {value}")
        except ValueError as error:
            if valid or not str(error):
                raise

    set_esdf(a["max_distance_m"])
    for op in a["ops"]:
        try:
            if op[0] == "depth":
                tsdf.integrate_depth(op[1], make_camera(op[2]), op[3])
            elif op[0] == "points":
                tsdf.integrate_points(op[1], op[2])
            elif op[0] == "set_esdf":
                set_esdf(op[1])
            elif op[0] == "clear":
                tsdf.clear()
            elif max_distance:  # the default cap may not suit hostile voxel sizes
                (tsdf.esdf_update if op[0] == "update" else tsdf.esdf_recompute)()
        except (ValueError, TypeError, IndexError, RuntimeError) as error:
            if not str(error):
                raise
    if not max_distance:
        return {"skipped": True}
    tsdf.esdf_update()
    distance, gradient = tsdf.esdf_distance(a["query"])
    voxels = tsdf.esdf_voxels()
    lo, hi, band_cap = a["band"]
    band_valid = (
        all(math.isfinite(v) for v in a["band"])
        and lo < hi
        and config.voxel_size_m <= band_cap <= 1e6
    )
    try:
        band = tsdf.esdf_band_slice(lo, hi, band_cap)
        if not band_valid:
            problems.append(f"esdf_band_slice accepted band {a['band']}")
    except ValueError as error:
        if band_valid or not str(error):
            raise
        band = None
    window = None
    if band is not None:
        cx, cy, side, cells = a["window"]
        window_valid = (
            math.isfinite(cx)
            and math.isfinite(cy)
            and math.isfinite(side)
            and 0 <= side <= 1e5
            and 1 <= cells <= 2**28
        )
        try:
            grid, capped = tsdf.slice_window(cx, cy, side, cells)
            if not window_valid:
                problems.append(f"slice_window accepted {a['window']}")
            window = (
                grid,
                capped,
                tsdf.esdf_band_slice(lo, hi, band_cap, grid),
                tsdf.esdf_band_slice(lo, hi, band_cap, grid, a["padding_bound"]),
            )
        except (ValueError, TypeError) as error:  # TypeError: a count beyond int64
            if window_valid or not str(error):
                raise
    return {
        "problems": problems,
        "band": band,
        "window": window,
        "max": max_distance[-1],
        "distance": distance,
        "gradient": gradient,
        "voxel_distance": voxels["distance"],
        "blocks": (tsdf.esdf_block_count, tsdf.block_count),
    }


def garbage_esdf(a: dict[str, Any], r: Any) -> str | None:
    if r.get("skipped"):
        return None
    if r["problems"]:
        return r["problems"][0]
    if r["blocks"][0] > r["blocks"][1]:
        return f"{r['blocks'][0]} ESDF blocks for {r['blocks'][1]} TSDF blocks"
    band = r["band"]
    if band is not None:
        d = band["distance"]
        if d.shape != (band["grid"].size_y, band["grid"].size_x):
            return f"band slice {d.shape} for a {band['grid']}"
        known = d[np.isfinite(d)]
        if np.isinf(d).any() or (np.abs(known) > a["band"][2] + 1e-6).any():
            return "a band slice distance that is infinite or beyond its cap"
        if (band["columns_occupied"], band["columns_free"]) != (
            int((known < 0).sum()),
            int((known > 0).sum()),
        ):
            return "band slice column counts disagree with its signs"
    if r["window"] is not None:
        problem = garbage_window(a["window"][3], band, *r["window"][:3]) or garbage_padding(
            a["padding_bound"], r["window"][2], r["window"][3]
        )
        if problem:
            return problem
    v = r["voxel_distance"]
    if not (np.isfinite(v) & (np.abs(v) <= r["max"] + 1e-6)).all():
        return "a known ESDF voxel that is not finite or beyond the cap"
    pts = np.asarray(a["query"], dtype=float)
    d, g = r["distance"], r["gradient"]
    if d.shape != (len(pts),) or g.shape != (len(pts), 3):
        return f"esdf_distance shapes {d.shape}, {g.shape} for {len(pts)} points"
    known = np.isfinite(d)
    if (np.abs(d[known]) > r["max"] + 1e-6).any() or not np.isfinite(g[known]).all():
        return "an interpolated distance beyond the cap or a non-finite gradient"
    bad = ~np.isfinite(pts).all(axis=1) | (np.abs(pts).max(axis=1, initial=0) > 1e6)
    if (bad & known).any():
        return f"esdf_distance at {pts[bad & known][0].tolist()} is not NaN"
    return None


def garbage_window(
    max_cells: int, whole: dict[str, Any], grid: Any, capped: bool, band: dict[str, Any]
) -> str | None:
    """A slice window within the cap and the whole map's grid, whose band ESDF is the whole
    map's there, value for value."""
    nx, ny = grid.size_x, grid.size_y
    if nx * ny > max_cells:
        return f"a slice window of {nx} x {ny} cells over the cap {max_cells}"
    if nx * ny == 0:
        return None if band["distance"].size == 0 else "values in an empty slice window"
    g0 = whole["grid"]
    x0 = round((grid.origin_x - g0.origin_x) / g0.resolution)
    y0 = round((grid.origin_y - g0.origin_y) / g0.resolution)
    if x0 < 0 or y0 < 0 or x0 + nx > g0.size_x or y0 + ny > g0.size_y:
        return f"slice window {grid} beyond the map's {g0}"
    expected = whole["distance"][y0 : y0 + ny, x0 : x0 + nx]
    if not np.array_equal(band["distance"], expected, equal_nan=True):
        return f"the band ESDF in window {grid} differs from the whole map's"
    return None


def garbage_padding(bound: int, free: dict[str, Any], bounded: dict[str, Any]) -> str | None:
    """The band ESDF with its padding bounded: within the bound (or the grid alone), the same
    known columns, and no value nearer than the unbounded one's."""
    cells = free["distance"].size
    if bound > 0 and bounded["columns_computed"] > max(bound, cells):
        return f"{bounded['columns_computed']} columns computed over the bound {bound}"
    if bounded["padding_voxels"] > free["padding_voxels"]:
        return "a bounded padding wider than the free one"
    if bounded["padding_cut"] != (bounded["padding_voxels"] < free["padding_voxels"]):
        return "padding_cut disagrees with the padding"
    got, want = bounded["distance"], free["distance"]
    if not np.array_equal(np.isnan(got), np.isnan(want)):
        return "a bounded padding changed which columns are known"
    known = ~np.isnan(want)
    if np.any(np.abs(got[known]) < np.abs(want[known])):
        return "a bounded padding read a distance nearer than the whole map's"
    return None


def gen_octree(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.15)
    config = {
        "resolution_m": g.f(0.05, 0.3),
        "prob_hit": g.f(0.55, 0.9),
        "prob_miss": g.f(0.1, 0.45),
        "max_range_m": g.f(2, 8),
        "depth_stride_px": g.i(1, 8, nasty=INT32_NASTY),
    }
    ops: list[tuple[Any, ...]] = []
    for _ in range(int(rng.integers(1, 4))):
        if g.b():
            ops.append(
                ("points", g.array((int(g.pick((0, 1, 10, 50))), 3), -3, 3), g.array((3,), -1, 1))
            )
        else:
            cam = camera_args(g)
            ops.append(("depth", depth_args(g, cam["shape"]), cam, pose_matrix(g)))
    return {"config": config, "ops": ops, "query": sample_points(g), "write": g.chance(0.1)}


def call_octree(a: dict[str, Any]) -> Any:
    c = core()
    config = configure(c.OctreeConfig(), a["config"])
    tree = c.OccupancyOctree(config)
    for op in a["ops"]:
        try:
            if op[0] == "points":
                tree.insert_points(op[1], op[2])
            else:
                tree.insert_depth(op[1], make_camera(op[2]), op[3])
        except (ValueError, TypeError) as error:
            if not str(error):
                raise
    if a["write"]:
        with tempfile.TemporaryDirectory() as d:
            tree.write_binary(os.path.join(d, "map.bt"))
    return {
        "valid": config.validate(),
        "log_odds": tree.log_odds(a["query"]),
        "occupied": tree.occupied(),
        "leaves": tree.leaf_count,
    }


def garbage_octree(a: dict[str, Any], r: Any) -> str | None:
    if r["valid"]:
        return f"OccupancyOctree accepted an invalid config ({r['valid']})"
    lod = r["log_odds"]
    if np.isinf(lod).any():
        return "infinite log-odds"
    pts = np.asarray(a["query"])
    bad = ~np.isfinite(pts).all(axis=1)
    if (bad & np.isfinite(lod)).any():
        return f"log-odds {lod[bad & np.isfinite(lod)][0]} at a non-finite point"
    if not all_finite(r["occupied"]):
        return "non-finite occupied centres"
    return None


def gen_slice_distance(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    shape = (int(rng.integers(0, 40)), int(rng.integers(0, 40)))
    s = rng.choice([-1, 0, 0, 0, 1], size=shape).astype(np.int8)
    return {
        "slice": s if g.chance(0.85) else g.array(shape, -2, 2, np.int8),
        "resolution": g.f(0.02, 0.2),
        "max_distance_m": g.f(0, 3),
    }


def call_slice_distance(a: dict[str, Any]) -> Any:
    return core().slice_distance(a["slice"], a["resolution"], a["max_distance_m"])


def garbage_slice_distance(a: dict[str, Any], d: Any) -> str | None:
    s = a["slice"]
    if not (isinstance(s, np.ndarray) and s.ndim == 2 and s.dtype == np.int8):
        return None
    res, cap = a["resolution"], a["max_distance_m"]
    if not (math.isfinite(res) and res > 0):
        return f"accepted resolution {res}"
    if d.shape != s.shape:
        return f"shape {d.shape} for a slice {s.shape}"
    if (~np.isnan(d[s < 0])).any():
        return "a distance on an unknown cell"
    known = d[s >= 0]
    if np.isnan(known).any() or (known < 0).any() or (known > cap + 1e-6).any():
        return f"distances outside [0, {cap}] on known cells"
    if (d[s > 0] != 0).any():
        return "non-zero distance on an occupied cell"
    return None


# ----------------------------------------------------------------------------- message checks
class Driver:
    """The C++ message-check driver, one per worker process, restarted after it dies."""

    def __init__(self) -> None:
        self.proc: subprocess.Popen[bytes] | None = None
        self.stderr: Any = None

    def path(self) -> Path:
        explicit = os.environ.get("FUZZ_DRIVER")
        if explicit:
            return Path(explicit)
        for prefix in os.environ.get("CMAKE_PREFIX_PATH", "").split(":"):
            candidate = Path(prefix) / "lib" / "downstream_perception" / "fuzz_message_checks"
            if candidate.is_file():
                return candidate
        raise HarnessError("fuzz_message_checks not found (catkin_make fuzz_message_checks)")

    def ask(self, kind: str, payload: bytes) -> str:
        if self.proc is None or self.proc.poll() is not None:
            self.stderr = tempfile.TemporaryFile()
            self.proc = subprocess.Popen(
                [str(self.path())],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=self.stderr,
            )
        assert self.proc.stdin is not None and self.proc.stdout is not None
        try:
            self.proc.stdin.write(f"{kind} {len(payload)}\n".encode() + payload)
            self.proc.stdin.flush()
            line = self.proc.stdout.readline()
        except BrokenPipeError:
            line = b""
        if not line:
            self.proc.wait()
            code = self.proc.returncode
            self.stderr.seek(0)
            tail = self.stderr.read().decode(errors="replace").strip().splitlines()[-15:]
            self.proc = None
            raise TargetCrashed(f"fuzz_message_checks died (status {code})\n" + "\n".join(tail))
        return line.decode(errors="replace").rstrip("\n")


_DRIVER = Driver()


def ask_driver(kind: str, msg: Any) -> str:
    buffer = io.BytesIO()
    try:
        msg.serialize(buffer)
    except Exception as error:  # noqa: BLE001 (genpy raises struct.error and friends)
        raise HarnessError(f"cannot serialize the {kind} message: {error}") from error
    answer = _DRIVER.ask(kind, buffer.getvalue())
    verdict, _, detail = answer.partition(" ")
    if verdict == "accept":
        return "accept"
    if verdict == "reject":
        raise ValueError(detail)
    if verdict == "garbage":
        return "garbage: " + detail
    if verdict == "exception":
        raise TargetCrashed("uncaught exception in a consumer (kills the nodelet): " + detail)
    raise HarnessError(answer)


def garbage_driver(a: dict[str, Any], answer: Any) -> str | None:
    return answer[len("garbage: ") :] if answer.startswith("garbage: ") else None


def f32(value: float) -> float:
    with np.errstate(over="ignore"):
        return float(np.float32(value))


def f32_array(a: np.ndarray) -> np.ndarray:
    with np.errstate(over="ignore"):
        return a.astype(np.float32)


def stamp(msg: Any, g: Gen) -> Any:
    import rospy

    msg.header.stamp = rospy.Time(int(g.rng.integers(1, 2**31)), int(g.rng.integers(0, 10**9)))
    msg.header.frame_id = g.pick(("laser", "camera", "", "x" * 1000))
    return msg


def gen_msg_scan(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    n = int(g.pick((0, 1, 2, 90, 360, 1000)))
    angle_min = g.f(-PI, 0)
    inc = g.f(0.001, 2 * PI / max(n, 1))
    angle_max = angle_min + inc * (n - 1) if g.chance(0.8) else g.f(-PI, PI)
    return {
        "ranges": f32_array(g.floats((n,), 0, 20, 0.1)),
        "intensities": f32_array(
            g.floats((n if g.chance(0.8) else int(g.pick((0, 1, n + 1))),), 0, 100)
        ),
        "angle_min": angle_min,
        "angle_max": angle_max,
        "angle_increment": inc,
        "time_increment": g.f(0, 1e-4),
        "scan_time": g.f(0, 0.1),
        "range_min": g.f(0, 0.2),
        "range_max": g.f(5, 30),
    }


def call_msg_scan(a: dict[str, Any]) -> Any:
    from sensor_msgs.msg import LaserScan

    msg = LaserScan()
    for key, value in a.items():  # float32 fields: 1e300 arrives as +Inf
        setattr(msg, key, value.tolist() if isinstance(value, np.ndarray) else f32(value))
    return ask_driver("scan", stamp(msg, Gen(np.random.default_rng(0))))


def gen_msg_cloud(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    x_off = int(g.pick((0, 0, 0, 4, 16, 4000, 4_000_000_000, 2**32 - 4)))
    names = (
        ["x", "y", "z"]
        if g.chance(0.9)
        else g.pick((["x", "y"], ["x", "x", "z"], ["z", "y", "x"], []))
    )
    fields = []
    for k, name in enumerate(names):
        offset = x_off + 4 * k if g.chance(0.9) else int(g.pick(UINT32_NASTY))
        datatype = 7 if g.chance(0.92) else int(g.pick((0, 1, 8, 255)))
        fields.append(
            {
                "name": name,
                "offset": offset % 2**32,
                "datatype": datatype,
                "count": 1 if g.chance(0.95) else int(g.pick((0, 2**32 - 1))),
            }
        )
    if g.chance(0.2):
        fields.append(
            {"name": "intensity", "offset": (x_off + 12) % 2**32, "datatype": 7, "count": 1}
        )
    point_step = x_off + 12 + int(g.pick((0, 0, 4))) if g.chance(0.8) else int(g.pick(UINT32_NASTY))
    point_step %= 2**32
    width = g.i(1, 40, 0.2, UINT32_NASTY) % 2**32
    height = g.i(1, 3, 0.2, UINT32_NASTY) % 2**32
    row_step = (
        (width * point_step + int(g.pick((0, 0, 0, 4))))
        if g.chance(0.8)
        else int(g.pick(UINT32_NASTY))
    )
    row_step %= 2**32
    consistent = row_step * height
    if consistent <= 1 << 16 and g.chance(0.85):
        size = consistent
    else:
        size = int(g.pick((0, 1, 12, 100, 4096)))
    data = f32_array(g.floats((size // 4 + 1,), -5, 5, 0.1)).tobytes()[:size]
    return {
        "fields": fields,
        "point_step": point_step,
        "width": width,
        "height": height,
        "row_step": row_step,
        "is_bigendian": g.chance(0.05),
        "is_dense": g.b(),
        "data": data,
    }


def call_msg_cloud(a: dict[str, Any]) -> Any:
    from sensor_msgs.msg import PointCloud2, PointField

    msg = PointCloud2()
    msg.fields = [
        PointField(name=f["name"], offset=f["offset"], datatype=f["datatype"], count=f["count"])
        for f in a["fields"]
    ]
    for key in ("point_step", "width", "height", "row_step", "is_bigendian", "is_dense", "data"):
        setattr(msg, key, a[key])
    return ask_driver("cloud", stamp(msg, Gen(np.random.default_rng(0))))


def gen_msg_pose(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    q = np.array([g.f(-1, 1, 0.1) for _ in range(4)])
    if g.chance(0.6) and all_finite(q) and np.linalg.norm(q) > 0:
        q = q / np.linalg.norm(q)
    return {
        "position": [g.f(-100, 100) for _ in range(3)],
        "orientation": q.tolist(),
        "frame": g.pick(("map", "", "odom")),
    }


def call_msg_pose(a: dict[str, Any]) -> Any:
    from geometry_msgs.msg import PoseStamped

    msg = stamp(PoseStamped(), Gen(np.random.default_rng(0)))
    msg.header.frame_id = a["frame"]
    p, q = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z = a["position"]
    q.x, q.y, q.z, q.w = a["orientation"]
    return ask_driver("pose", msg)


def gen_msg_depth(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng)
    encoding = g.pick(
        ("32FC1", "32FC1", "16UC1", "16UC1", "mono16", "rgb8", "", "32FC1\0x", "8UC1")
    )
    pixel = 4 if encoding == "32FC1" else 2
    width = g.i(1, 64, 0.2, UINT32_NASTY) % 2**32
    height = g.i(1, 48, 0.2, UINT32_NASTY) % 2**32
    step = (
        (width * pixel + int(g.pick((0, 0, 0, 2, 8))))
        if g.chance(0.85)
        else int(g.pick(UINT32_NASTY))
    )
    step %= 2**32
    consistent = step * height
    size = (
        consistent
        if consistent <= 1 << 16 and g.chance(0.85)
        else int(g.pick((0, 1, 100, 4096, max(consistent - 1, 0) % 70000)))
    )
    data = f32_array(g.floats((size // 4 + 1,), 0, 5, 0.1)).tobytes()[:size]
    return {
        "encoding": encoding,
        "width": width,
        "height": height,
        "step": step,
        "is_bigendian": int(g.chance(0.05)),
        "data": data,
    }


def call_msg_depth(a: dict[str, Any]) -> Any:
    from sensor_msgs.msg import Image

    msg = stamp(Image(), Gen(np.random.default_rng(0)))
    for key, value in a.items():
        setattr(msg, key, value)
    return ask_driver("depth", msg)


# ----------------------------------------------------------------------------- 3-D voxel map
WINDOW_NASTY = (0, -1, 65537, 2**31, -(2**31))  # invalid sides only: a valid huge one is slow


def voxel_config_args(g: Gen) -> dict[str, Any]:
    return {
        "resolution_m": g.f(0.02, 0.2, 0.05),
        "z_resolution_m": g.f(0.02, 0.3, 0.05),
        "origin_z_m": g.f(-0.5, 0.5, 0.05),
        "z_voxels": g.i(1, 40, 0.05, (0, -1, 1024, 1025, 2**31 - 1, -(2**31))),
        "mark_threshold": g.i(0, 3, 0.05, INT32_NASTY),
        "unknown_threshold": g.i(0, 20, 0.05, INT32_NASTY),
        "min_obstacle_height_m": g.f(0.0, 0.3, 0.05),
        "max_obstacle_height_m": g.f(0.5, 2.0, 0.05),
        "decay_time_s": g.f(0.0, 5.0, 0.05) if g.b() else 0.0,
        "max_memory_mib": g.f(0.01, 8.0, 0.05),
    }


def voxel_ray_config_args(g: Gen) -> dict[str, Any]:
    return {
        "obstacle_max_range_m": g.f(0.5, 5.0, 0.1),
        "raytrace_max_range_m": g.f(0.5, 6.0, 0.1),
        "no_return_range_m": g.f(0.0, 6.0, 0.1),
        "marking": g.b() or g.b(),
        "clearing": g.b() or g.b(),
        "one_ray_per_end_voxel": g.b(),
    }


def gen_voxel_map(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.2)
    ops: list[tuple[Any, ...]] = []
    for _ in range(int(rng.integers(1, 7))):
        op = g.pick(("points", "points", "depth", "window", "columns", "prune", "clear"))
        if op == "points":
            n, m = int(g.pick((0, 1, 40))), int(g.pick((0, 1, 10)))
            ops.append(
                (
                    op,
                    g.array((3,), -1, 1),
                    g.array((n, 3), -2, 4),
                    g.array((m, 3), -2, 4),
                    g.f(0, 10, 0.1),
                    voxel_ray_config_args(g),
                )
            )
        elif op == "depth":
            cam = camera_args(g)
            ops.append(
                (op, depth_args(g, cam["shape"]), cam, pose_matrix(g), g.f(0, 10, 0.1))
                + (voxel_ray_config_args(g), g.b(), g.i(1, 3, 0.1, INT32_NASTY))
                + (g.pick(("ray", "frustum", "frustum", "")),)
            )
        elif op == "columns":
            n = int(g.pick((0, 1, 30)))
            columns = rng.integers(-5, 125, size=(n, 2))
            if g.chance(0.1):
                columns = np.array([[2**62, -(2**62)], [2**31, 0]] * (n // 2 + 1))
            if g.chance(0.1):
                columns = g.array((n, 3), -5, 125)  # a wrong shape or type
            ops.append((op, columns, g.f(0, 10, 0.1)))
        elif op == "window":
            ops.append(
                (op, *(g.i(-50, 50, 0.1, INT32_NASTY) for _ in range(2)))
                + tuple(g.i(1, 120, 0.1, WINDOW_NASTY) for _ in range(2))
            )
        else:
            ops.append((op, g.f(0, 20, 0.1)))
    return {
        "config": voxel_config_args(g),
        "anchor": (g.f(-3, 0, 0.08), g.f(-3, 0, 0.08)),
        "size": (g.i(1, 120, 0.08, WINDOW_NASTY), g.i(1, 120, 0.08, WINDOW_NASTY)),
        "ops": ops,
        "now": g.f(0, 20, 0.1),
    }


def make_voxel_config(a: dict[str, Any]) -> Any:
    return configure(core().VoxelMapConfig(), a)


def call_voxel_map(a: dict[str, Any]) -> Any:
    c = core()
    config = make_voxel_config(a["config"])
    valid = config.validate()
    try:
        vmap = c.VoxelMap(config, a["anchor"][0], a["anchor"][1], *a["size"])
    except (ValueError, TypeError) as error:
        if not str(error):
            raise
        return {"skipped": True, "valid": valid}
    problems: list[str] = []
    moved = False
    for op in a["ops"]:
        try:
            if op[0] == "points":
                rays = configure(c.VoxelRayConfig(), op[5])
                s = vmap.integrate(op[1], op[2], op[3], op[4], rays)
                if s["marked"] + s["cleared"] > s["voxels_walked"] + s["rays"]:
                    problems.append(f"more updates than visits: {s}")
            elif op[0] == "depth":
                rays = configure(c.VoxelRayConfig(), op[5])
                s = vmap.integrate_depth(
                    op[1], make_camera(op[2]), op[3], op[4], rays, op[6], op[7], op[8]
                )
                if s["marked"] + s["cleared"] > s["voxels_walked"] + s["rays"]:
                    problems.append(f"more updates than visits: {s}")
            elif op[0] == "columns":
                s = vmap.clear_columns(op[1], op[2])
                if s["marked"] or s["cleared"] > len(op[1]) * vmap.shape[2]:
                    problems.append(f"clear_columns: {s} for {len(op[1])} columns")
            elif op[0] == "window":
                vmap.set_window(*op[1:])
                moved = True
            elif op[0] == "prune":
                vmap.prune(op[1])
            else:
                vmap.clear()
        except (ValueError, TypeError, IndexError) as error:
            if not str(error):
                raise
        if not moved and vmap.blocks > vmap.max_blocks:
            problems.append(f"{vmap.blocks} blocks with max_blocks {vmap.max_blocks}")
    return {
        "valid": valid,
        "problems": problems,
        "shape": vmap.shape,
        "origin": vmap.window_origin,
        "costs": vmap.project(a["now"]),
        "occupied": vmap.occupied_centres(a["now"]),
        "config": vmap.config,
    }


def garbage_voxel_map(a: dict[str, Any], r: Any) -> str | None:
    if r.get("skipped"):
        return None
    if r["valid"]:
        return f"VoxelMap accepted an invalid config ({r['valid']})"
    if r["problems"]:
        return r["problems"][0]
    nx, ny, nz = r["shape"]
    costs = r["costs"]
    if costs.shape != (ny, nx) or not np.isin(costs, (0, 254, 255)).all():
        return f"project gave shape {costs.shape} or values {np.unique(costs)[:5]}"
    occ = np.asarray(r["occupied"], dtype=float)
    if occ.size:
        cfg = r["config"]
        lo = np.array([r["origin"][0], r["origin"][1], cfg.origin_z_m])
        hi = lo + np.array([nx * cfg.resolution_m, ny * cfg.resolution_m, nz * cfg.z_resolution_m])
        slack = 1e-3 * np.maximum(1.0, np.abs(hi))
        if not np.isfinite(occ).all() or ((occ < lo - slack) | (occ > hi + slack)).any():
            return "an occupied voxel centre outside the window or not finite"
    return None


def gen_voxel_ray(rng: np.random.Generator) -> dict[str, Any]:
    g = Gen(rng, 0.2)
    box = [g.i(1, 30, 0.15, WINDOW_NASTY) for _ in range(3)]
    if g.chance(0.2):
        box = g.array((3,), 1, 30)
    return {
        "box": box,
        "p0": g.array((3,), -5, 35),
        "p1": g.array((3,), -5, 35),
        "include_end": g.b(),
    }


def call_voxel_ray(a: dict[str, Any]) -> Any:
    return core().voxel_ray(a["box"], a["p0"], a["p1"], a["include_end"])


def garbage_voxel_ray(a: dict[str, Any], cells: Any) -> str | None:
    box = np.asarray(a["box"]).astype(np.int64).reshape(-1)  # (3,) or (3, 1): both accepted
    if cells.size == 0:
        return None
    if (cells < 0).any() or (cells >= box).any():
        return f"voxel {cells[((cells < 0) | (cells >= box)).any(axis=1)][0]} outside {box}"
    if len({tuple(c) for c in cells.tolist()}) != len(cells):
        return "a voxel visited twice"
    if (np.abs(np.diff(cells, axis=0)) > 1).any():
        return "consecutive voxels more than one step apart"
    return None


# ----------------------------------------------------------------------------- the list
def binding_targets() -> list[Target]:
    return [
        Target(
            "GridGeometry",
            gen_grid_geometry,
            call_grid_geometry,
            garbage_grid_geometry,
            ("GridGeometry",),
        ),
        Target(
            "bresenham_line", gen_bresenham, call_bresenham, garbage_bresenham, ("bresenham_line",)
        ),
        Target("ray_cells", gen_ray_cells, call_ray_cells, garbage_ray_cells, ("ray_cells",)),
        Target(
            "LogOddsGrid",
            gen_log_odds_grid,
            call_log_odds_grid,
            garbage_log_odds_grid,
            ("LogOddsGrid", "LogOddsConfig"),
        ),
        Target(
            "log_odds_of/probability_of",
            gen_log_odds_scalars,
            call_log_odds_scalars,
            garbage_log_odds_scalars,
            ("log_odds_of", "probability_of"),
        ),
        Target(
            "ScanIntegrator.integrate",
            gen_scan_integrate,
            call_scan_integrate,
            garbage_integration,
            ("ScanIntegrator", "ScanIntegratorConfig"),
        ),
        Target(
            "ScanIntegrator.integrate_moving",
            gen_scan_integrate_moving,
            call_scan_integrate_moving,
            garbage_integration,
            ("ScanIntegrator",),
        ),
        Target(
            "ScanIntegrator.integrate_cloud",
            gen_scan_integrate_cloud,
            call_scan_integrate_cloud,
            garbage_integration,
            ("ScanIntegrator",),
        ),
        Target(
            "se2 (compose/inverse/apply/...)",
            gen_se2,
            call_se2,
            garbage_se2,
            (
                "Pose2D",
                "compose",
                "inverse",
                "apply",
                "interpolate",
                "normalize_angle",
                "shortest_angular_distance",
            ),
        ),
        Target(
            "static_map",
            gen_static_map,
            call_static_map,
            garbage_static_map,
            ("StaticMapConfig", "static_map_values", "StaticMap"),
        ),
        Target(
            "occupancy_table",
            lambda rng: {},
            call_occupancy_table,
            garbage_occupancy_table,
            ("occupancy_table",),
        ),
        Target(
            "inflation_cost",
            gen_inflation_cost,
            call_inflation_cost,
            garbage_inflation_cost,
            ("inflation_cost", "InflationConfig"),
        ),
        Target(
            "inflate", gen_inflate, call_inflate, garbage_inflate, ("inflate", "InflationConfig")
        ),
        Target(
            "footprint_radii",
            gen_footprint_radii,
            call_footprint_radii,
            garbage_footprint_radii,
            ("footprint_radii",),
        ),
        Target(
            "footprint_cells",
            gen_footprint_cells,
            call_footprint_cells,
            garbage_footprint_cells,
            ("footprint_cells",),
        ),
        Target("iou", gen_iou, call_iou, garbage_iou, ("iou",)),
        Target("nms", gen_nms, call_nms, garbage_nms, ("nms",)),
        Target("mask_iou", gen_mask_iou, call_mask_iou, garbage_mask_iou, ("mask_iou",)),
        Target(
            "expected_smear",
            gen_expected_smear,
            call_expected_smear,
            garbage_expected_smear,
            ("expected_smear", "SeamLimits"),
        ),
        Target(
            "CorrectionMonitor",
            gen_correction_monitor,
            call_correction_monitor,
            garbage_correction_monitor,
            ("CorrectionMonitor", "CorrectionMonitorConfig"),
        ),
        Target(
            "prediction (uncertainty/swept/cells)",
            gen_prediction,
            call_prediction,
            garbage_prediction,
            (
                "PlanarTrack",
                "PredictionConfig",
                "uncertainty_radius",
                "swept_polygon",
                "predicted_cells",
                "recent_cells",
            ),
        ),
        Target(
            "chi_square_quantile",
            gen_chi_square,
            call_chi_square,
            garbage_chi_square,
            ("chi_square_quantile",),
        ),
        Target(
            "solve_assignment",
            gen_assignment,
            call_assignment,
            garbage_assignment,
            ("solve_assignment",),
        ),
        Target("Tracker", gen_tracker, call_tracker, garbage_tracker, ("Tracker", "TrackerConfig")),
        Target(
            "Tsdf",
            gen_tsdf,
            call_tsdf,
            garbage_tsdf,
            ("Tsdf", "TsdfConfig", "TsdfWeighting", "TsdfEdgeGuardRule", "PinholeCamera"),
        ),
        Target(
            "Esdf",
            gen_esdf,
            call_esdf,
            garbage_esdf,
            ("Tsdf", "EsdfConfig", "PinholeCamera"),
        ),
        Target(
            "OccupancyOctree",
            gen_octree,
            call_octree,
            garbage_octree,
            ("OccupancyOctree", "OctreeConfig", "PinholeCamera"),
        ),
        Target(
            "slice_distance",
            gen_slice_distance,
            call_slice_distance,
            garbage_slice_distance,
            ("slice_distance",),
        ),
        Target(
            "VoxelMap",
            gen_voxel_map,
            call_voxel_map,
            garbage_voxel_map,
            ("VoxelMap", "VoxelMapConfig", "VoxelRayConfig", "PinholeCamera"),
        ),
        Target("voxel_ray", gen_voxel_ray, call_voxel_ray, garbage_voxel_ray, ("voxel_ray",)),
    ]


def message_targets() -> list[Target]:
    return [
        Target(
            "msg checkScan (+consumers)",
            gen_msg_scan,
            call_msg_scan,
            garbage_driver,
            ("checkScan",),
        ),
        Target(
            "msg checkCloudLayout (+consumers)",
            gen_msg_cloud,
            call_msg_cloud,
            garbage_driver,
            ("checkCloudLayout",),
        ),
        Target("msg checkPose", gen_msg_pose, call_msg_pose, garbage_driver, ("checkPose",)),
        Target(
            "msg checkDepthImage (+conversion)",
            gen_msg_depth,
            call_msg_depth,
            garbage_driver,
            ("checkDepthImage", "depthImageToMetres"),
        ),
    ]


def _quiet(generate: Any) -> Any:
    """Generators cast NaN and 1e300 to float32 and ints on purpose: no warnings for that."""

    def run(rng: np.random.Generator) -> dict[str, Any]:
        with np.errstate(all="ignore"):
            return generate(rng)

    return run


def targets() -> list[Target]:
    return [
        dataclasses.replace(t, generate=_quiet(t.generate))
        for t in binding_targets() + message_targets()
    ]
