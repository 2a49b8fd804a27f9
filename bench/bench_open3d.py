#!/usr/bin/env python3
"""TSDF integration side by side with Open3D 0.19 (report, never assert).

Open3D is not a dependency: `make bench-open3d` installs open3d-cpu 0.19.0 into its own venv
(.ws/open3d-venv, which also sees the workspace's packages) and runs this script there. Both
integrate the same simulated room frames on one thread (OMP_NUM_THREADS=1) at 2 cm with a
truncation of 4 voxels. Rounds alternate between the integrators, so a slow phase of a shared
machine slows every one of them alike; the ratios are taken per round, then their median.

Usage: make bench-open3d   (or, where open3d imports: python3 bench/bench_open3d.py --rounds 6)
"""

from __future__ import annotations

import argparse
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from bench_tsdf import timed_frames  # bench/bench_tsdf.py, next to this file

VOXEL_M = 0.02
TRUNCATION_VOXELS = 4
FRAMES = 30


@dataclass
class Timing:
    frame_ms: list[float]  # each frame's integration
    mesh_ms: float  # one whole-mesh extraction after the last frame


# One integrator: given the frames' depths, poses and camera, integrates them all into a fresh
# map, then extracts the whole mesh once.
Integrator = Callable[[Sequence[np.ndarray], Sequence[np.ndarray], Any], Timing]


def timed(work: Callable[[], object]) -> float:
    t0 = time.perf_counter()
    work()
    return 1e3 * (time.perf_counter() - t0)


def ours(
    depths: Sequence[np.ndarray],
    poses: Sequence[np.ndarray],
    cam: Any,
    rule_before_defect_4: bool = False,
    incidence_window: bool = True,
    mesh_extrapolation: bool = True,
) -> Timing:
    """Default settings; rule_before_defect_4: the fixed-radius edge guard without the grazing
    reach (issue 22's rule before defect 4, cheaper per pixel); incidence_window False:
    incidences from each pixel's nearest neighbours only (incidence_window_radius_px 0);
    mesh_extrapolation False: mesh_extrapolate_voxels 0 (the mesh before 2026-12-06)."""
    import downstream_perception as dp

    config = dp.TsdfConfig()
    config.voxel_size_m = VOXEL_M
    config.truncation_voxels = TRUNCATION_VOXELS
    if rule_before_defect_4:
        config.edge_guard_rule = dp.TsdfEdgeGuardRule.FIXED_RADIUS
        config.grazing_reach_voxels = 0.0
    if not incidence_window:
        config.incidence_window_radius_px = 0
    if not mesh_extrapolation:
        config.mesh_extrapolate_voxels = 0.0
    tsdf = dp.Tsdf(config)
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    elapsed = timed_frames(tsdf.integrate_depth, depths, pinhole, poses)
    return Timing(elapsed, timed(tsdf.update_mesh))  # the first extraction meshes every block


def open3d_tensor(depths: Sequence[np.ndarray], poses: Sequence[np.ndarray], cam: Any) -> Timing:
    """VoxelBlockGrid on the CPU: block coordinates plus integration, per frame."""
    import open3d as o3d
    import open3d.core as o3c

    intrinsic = o3c.Tensor(
        np.array([[cam.fx, 0, cam.cx], [0, cam.fy, cam.cy], [0, 0, 1]], dtype=np.float64)
    )
    grid = o3d.t.geometry.VoxelBlockGrid(
        attr_names=("tsdf", "weight"),
        attr_dtypes=(o3c.float32, o3c.float32),
        attr_channels=((1), (1)),
        voxel_size=VOXEL_M,
        block_resolution=8,
        block_count=50000,
        device=o3c.Device("CPU:0"),
    )
    options = {
        "depth_scale": 1.0,
        "depth_max": 10.0,
        "trunc_voxel_multiplier": float(TRUNCATION_VOXELS),
    }
    # Open3D reads 0 as invalid; +Inf (no return) becomes the largest float, beyond depth_max.
    images = [o3d.t.geometry.Image(o3c.Tensor(np.nan_to_num(d, nan=0.0))) for d in depths]

    def integrate(image: Any, intrinsic: Any, extrinsic: Any) -> None:
        blocks = grid.compute_unique_block_coordinates(image, intrinsic, extrinsic, **options)
        grid.integrate(blocks, image, intrinsic, extrinsic, **options)

    extrinsics = [o3c.Tensor(np.linalg.inv(pose)) for pose in poses]
    elapsed = timed_frames(integrate, images, intrinsic, extrinsics)
    return Timing(elapsed, timed(lambda: grid.extract_triangle_mesh(weight_threshold=1.0)))


def open3d_legacy(depths: Sequence[np.ndarray], poses: Sequence[np.ndarray], cam: Any) -> Timing:
    """ScalableTSDFVolume without colour."""
    import open3d as o3d

    intrinsic = o3d.camera.PinholeCameraIntrinsic(
        cam.width, cam.height, cam.fx, cam.fy, cam.cx, cam.cy
    )
    colour = o3d.geometry.Image(np.zeros((cam.height, cam.width, 3), np.uint8))
    frames = [
        o3d.geometry.RGBDImage.create_from_color_and_depth(
            colour,
            o3d.geometry.Image(np.nan_to_num(d, nan=0.0)),
            depth_scale=1.0,
            depth_trunc=10.0,
            convert_rgb_to_intensity=False,
        )
        for d in depths
    ]
    volume = o3d.pipelines.integration.ScalableTSDFVolume(
        voxel_length=VOXEL_M,
        sdf_trunc=TRUNCATION_VOXELS * VOXEL_M,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.NoColor,
    )
    extrinsics = [np.linalg.inv(pose) for pose in poses]
    elapsed = timed_frames(volume.integrate, frames, intrinsic, extrinsics)
    return Timing(elapsed, timed(volume.extract_triangle_mesh))


def interleave(
    integrators: dict[str, Integrator],
    depths: Sequence[np.ndarray],
    poses: Sequence[np.ndarray],
    cam: Any,
    rounds: int,
) -> dict[str, list[Timing]]:
    """Each integrator's timing in each round; within a round they run in turn."""
    timings: dict[str, list[Timing]] = {name: [] for name in integrators}
    for _ in range(rounds):
        for name, integrate in integrators.items():
            timings[name].append(integrate(depths, poses, cam))
    return timings


def summarise(timings: dict[str, list[Timing]], reference: str) -> dict[str, dict[str, float]]:
    """Per integrator, over the rounds: the median and range of its median ms per frame, the
    median of those divided by the reference's in the same round (> 1: slower than the
    reference), and the same for the whole-mesh extraction."""

    def per_frame(name: str) -> np.ndarray:
        return np.array([np.median(t.frame_ms) for t in timings[name]])

    def mesh(name: str) -> np.ndarray:
        return np.array([t.mesh_ms for t in timings[name]])

    summary = {}
    for name in timings:
        v = per_frame(name)
        summary[name] = {
            "median_ms": float(np.median(v)),
            "min_ms": float(v.min()),
            "max_ms": float(v.max()),
            "ratio": float(np.median(v / per_frame(reference))),
            "mesh_ms": float(np.median(mesh(name))),
            "mesh_ratio": float(np.median(mesh(name) / mesh(reference))),
        }
    return summary


def markdown(results: dict[str, dict[str, dict[str, float]]], rounds: int) -> list[str]:
    lines = [
        "## TSDF integration side by side with Open3D 0.19 (one thread, 2 cm, same frames)",
        "",
        f"{rounds} alternating rounds of {FRAMES} frames, each ending with one whole-mesh "
        "extraction; per integrator the median over rounds of its median ms per frame (range) "
        "and of its time over ours in the same round.",
        "",
        "| image | integrator | integrate ms per frame (range) | × ours | whole mesh ms | × ours |",
        "|---|---|---|---|---|---|",
    ]
    for image, summary in results.items():
        for name, s in summary.items():
            lines.append(
                f"| {image} | {name} | {s['median_ms']:.2f} ({s['min_ms']:.2f}–{s['max_ms']:.2f})"
                f" | {s['ratio']:.2f} | {s['mesh_ms']:.1f} | {s['mesh_ratio']:.2f} |"
            )
    lines.append("")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=6, help="alternating rounds per image")
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error("--rounds must be at least 1")
    if os.environ.get("OMP_NUM_THREADS") != "1":
        raise SystemExit("set OMP_NUM_THREADS=1: the comparison is on one thread")
    from downstream_perception.sim.depth_camera import DepthCamera, circle_poses, room_scene

    scene = room_scene()
    poses = [np.asarray(T, dtype=np.float64) for T in circle_poses(FRAMES)]
    integrators: dict[str, Integrator] = {
        "downstream_perception": ours,
        "ours, fixed-radius guard": lambda d, p, c: ours(d, p, c, rule_before_defect_4=True),
        "ours, no incidence window": lambda d, p, c: ours(d, p, c, incidence_window=False),
        "ours, no mesh extrapolation": lambda d, p, c: ours(d, p, c, mesh_extrapolation=False),
        "Open3D tensor": open3d_tensor,
        "Open3D legacy": open3d_legacy,
    }
    results = {}
    for image, cam in (("320x240", DepthCamera()), ("640x480", DepthCamera.vga())):
        depths = [np.ascontiguousarray(cam.render(scene, T), dtype=np.float32) for T in poses]
        medians = interleave(integrators, depths, poses, cam, args.rounds)
        results[image] = summarise(medians, "downstream_perception")
    print("\n".join(markdown(results, args.rounds)))


if __name__ == "__main__":
    main()
