#!/usr/bin/env python3
"""Where two meshes of one accuracy-benchmark case differ: the observed samples one covers and
the other does not, per part of the scene (report, never assert).

One case of bench_tsdf_accuracy.py (scene, lattice offset, image, voxel, noise case: the very
frames and poses the benchmark integrates) is meshed twice: ours with --ours settings (A) and
either Open3D legacy (--against legacy, needs open3d) or ours with other settings (B). Each
observed sample (the surface the clean frames saw) is covered when it lies within the
benchmark's completeness radius of a mesh. The samples are attributed to the scene part nearest
to them: a room wall, or a box's face (and "edge" within a voxel of another face of that box),
a sphere or a cylinder. Printed: each mesh's completeness, then per part the samples, the share
each mesh covers, and how many B covers and A does not ("lost") and the other way round
("gained"), parts with the most lost first.

Why: the completeness figures say how much surface a rule loses, this says where, which the
issue notes needed every time (a box's edge on a plane of voxel centres, a board's end faces);
it replaces the scratch scripts written for it.

Usage: python3 bench/tsdf_gap_trace.py --scene furniture --offset 0 --voxel-cm 2
         [--image 320x240] [--noise 0] [--ours KEY=VALUE,...] [--against legacy|KEY=VALUE,...]
         [--frames 30] [--top 12] [--json FILE]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

COMPLETENESS_RADIUS_M = 0.02  # bench_tsdf_accuracy's (tsdf_eval.score_mesh's default)
AXES = "xyz"


def load_bench() -> Any:
    """bench_tsdf_accuracy.py, beside this file (a script, not a package: imported with its
    folder on sys.path, as a script run from there has it)."""
    folder = str(Path(__file__).resolve().parent)
    if folder not in sys.path:
        sys.path.insert(0, folder)
    import bench_tsdf_accuracy

    return bench_tsdf_accuracy


def face_labels(q: np.ndarray, half: np.ndarray, voxel_m: float) -> list[str]:
    """Face of an axis-aligned box for points q (N, 3) relative to its centre, half its extents:
    the axis whose slab the point is farthest out of (or least deep in), with its sign; "edge"
    added where another axis is within a voxel of its face too."""
    out_of = np.abs(q) - half  # > 0 outside that axis's slab
    order = np.argsort(-out_of, axis=1)
    axis = order[:, 0]
    rows = np.arange(len(q))
    sign = np.where(q[rows, axis] >= 0.0, "+", "-")
    edge = np.abs(out_of[rows, order[:, 1]]) <= voxel_m
    return [f"{AXES[a]}{s}{' edge' if e else ''}" for a, s, e in zip(axis, sign, edge, strict=True)]


def part_labels(scene: Any, points: np.ndarray, voxel_m: float) -> np.ndarray:
    """The scene part nearest to each point (N, 3): 'wall x-' (the room's faces), 'box 0 z+'
    (or 'box 0 z+ edge'), 'sphere 0', 'cylinder 0'."""
    from downstream_perception.sim.depth_camera import box_signed_distance

    p = np.asarray(points, dtype=float)
    lo, hi = np.asarray(scene.room_min), np.asarray(scene.room_max)
    walls = np.concatenate([p - lo, hi - p], axis=1)  # x-, y-, z-, x+, y+, z+
    wall_names = [f"wall {a}-" for a in AXES] + [f"wall {a}+" for a in AXES]
    distances = [walls]
    names: list[str] = list(wall_names)
    for k, box in enumerate(scene.boxes):
        distances.append(np.abs(box_signed_distance(p, box))[:, None])
        names.append(f"box {k}")
    for k, sphere in enumerate(scene.spheres):
        d = np.abs(np.linalg.norm(p - np.asarray(sphere.center), axis=1) - sphere.radius)
        distances.append(d[:, None])
        names.append(f"sphere {k}")
    for k, cyl in enumerate(scene.cylinders):
        radial = np.abs(np.linalg.norm(p[:, :2] - np.asarray(cyl.center_xy), axis=1) - cyl.radius)
        distances.append(radial[:, None])
        names.append(f"cylinder {k}")
    nearest = np.argmin(np.concatenate(distances, axis=1), axis=1)
    labels = np.array([names[i] for i in nearest], dtype=object)
    for k, box in enumerate(scene.boxes):
        on = np.flatnonzero(labels == f"box {k}")
        if len(on):
            q = p[on] - np.asarray(box.center)
            faces = face_labels(q, np.asarray(box.half_extents), voxel_m)
            labels[on] = [f"box {k} {f}" for f in faces]
    return labels


@dataclass
class PartGap:
    part: str
    samples: int
    covered_a: float
    covered_b: float
    lost: int  # B covers, A does not
    gained: int  # A covers, B does not


def gaps(labels: np.ndarray, near_a: np.ndarray, near_b: np.ndarray) -> list[PartGap]:
    """Per part: samples, each mesh's covered share, lost and gained; most lost first, then the
    largest net loss."""
    out = []
    for part in sorted(set(labels)):
        m = labels == part
        out.append(
            PartGap(
                str(part),
                int(m.sum()),
                float(near_a[m].mean()),
                float(near_b[m].mean()),
                int((near_b & ~near_a & m).sum()),
                int((near_a & ~near_b & m).sum()),
            )
        )
    return sorted(out, key=lambda g: (-g.lost, g.gained - g.lost, g.part))


def trace(
    bench: Any,
    scene_name: str,
    fraction: float,
    voxel_m: float,
    image: str = "320x240",
    noise_index: int = 0,
    ours: str = "default",
    against: str = "legacy",
    frames: int = 30,
) -> tuple[dict[str, float], list[PartGap]]:
    """Meshes A (ours with `ours` settings) and B (legacy, or ours with `against` settings) of the
    case; returns each one's completeness and the per-part gaps."""
    from downstream_perception.sim.scenes import accuracy_scene
    from downstream_perception.tsdf_eval import near_mesh

    cam = bench.camera(image)
    clean, base_observed = bench.scene_frames(cam, scene_name, frames)
    offset = (fraction * voxel_m,) * 3
    scene, poses = accuracy_scene(scene_name, offset, frames)
    observed = base_observed + np.asarray(offset)
    seed = bench.scene_seed(scene_name, fraction)
    depths, at = bench.noisy_frames(clean, poses, bench.NOISES[noise_index], seed=seed)
    integrate_a = bench.ours(settings=bench.parse_settings(ours))
    integrate_b = (
        bench.open3d_legacy
        if against == "legacy"
        else bench.ours(settings=bench.parse_settings(against))
    )
    near = []
    for integrate in (integrate_a, integrate_b):
        vertices, triangles = bench.weld(*integrate(depths, at, cam, voxel_m))
        near.append(near_mesh(observed, vertices, triangles, COMPLETENESS_RADIUS_M))
    labels = part_labels(scene, observed, voxel_m)
    completeness = {"a": float(near[0].mean()), "b": float(near[1].mean())}
    return completeness, gaps(labels, near[0], near[1])


def markdown(completeness: dict[str, float], rows: Sequence[PartGap], top: int) -> list[str]:
    lines = [
        f"completeness: A {completeness['a']:.4f}, B {completeness['b']:.4f}",
        "",
        "| part | samples | A covers | B covers | lost (B, not A) | gained (A, not B) |",
        "|---|---|---|---|---|---|",
    ]
    for g in rows[:top]:
        lines.append(
            f"| {g.part} | {g.samples} | {g.covered_a:.3f} | {g.covered_b:.3f} | {g.lost} | "
            f"{g.gained} |"
        )
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    from downstream_perception.sim.scenes import ACCURACY_SCENES

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", required=True, choices=list(ACCURACY_SCENES))
    parser.add_argument("--offset", type=float, default=0.0, help="fraction of a voxel")
    parser.add_argument("--voxel-cm", type=float, default=2.0)
    parser.add_argument("--image", choices=("320x240", "640x480"), default="320x240")
    parser.add_argument("--noise", type=int, default=0, help="index into the noise cases (0 clean)")
    parser.add_argument("--ours", default="default", help="A: TsdfConfig key=value,...")
    parser.add_argument(
        "--against", default="legacy", help="B: 'legacy' (Open3D) or TsdfConfig key=value,..."
    )
    parser.add_argument("--frames", type=int, default=30)
    parser.add_argument("--top", type=int, default=12, help="parts printed")
    parser.add_argument("--json", type=Path, help="write every part's figures here")
    args = parser.parse_args(argv)
    bench = load_bench()
    if not 0 <= args.noise < len(bench.NOISES):
        parser.error(f"--noise must be in [0, {len(bench.NOISES) - 1}]")
    if not (args.voxel_cm > 0.0 and args.frames > 0):
        parser.error("--voxel-cm and --frames must be > 0")
    if args.against == "legacy" and importlib.util.find_spec("open3d") is None:
        parser.error("--against legacy needs open3d (make bench-open3d installs it)")
    ours_settings = [args.ours] + ([] if args.against == "legacy" else [args.against])
    try:  # before the frames are rendered
        for settings in ours_settings:
            bench.parse_settings(settings)
    except ValueError as error:
        parser.error(str(error))
    completeness, rows = trace(
        bench, args.scene, args.offset, args.voxel_cm / 100.0, args.image, args.noise,
        args.ours, args.against, args.frames,
    )  # fmt: skip
    print("\n".join(markdown(completeness, rows, args.top)))
    if args.json:
        args.json.write_text(
            json.dumps({"completeness": completeness, "parts": [asdict(g) for g in rows]}, indent=1)
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
