"""TSDF benchmark (report, never assert): integration ms per frame, meshing, memory and accuracy on
the simulated room (30 frames on a circle), at 320x240 and 640x480, 2 cm and 5 cm voxels; the ESDF
(incremental update per frame and full recomputation) at 5 cm.

Used by bench.py; runnable alone: python3 bench/bench_tsdf.py
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

# Open3D 0.19 on this machine kind, single thread (anchor notes): integrate ms per frame
# (legacy ScalableTSDFVolume, tensor VoxelBlockGrid), by (image, voxel).
OPEN3D_MS = {
    ("320x240", 0.02): (16.37, 8.19),
    ("640x480", 0.02): (24.47, 15.28),
    ("320x240", 0.05): (3.07, 3.70),
    ("640x480", 0.05): (4.57, 5.06),
}


def timed_frames(
    insert: Callable[[np.ndarray, Any, np.ndarray], Any],
    depths: list[np.ndarray],
    camera: Any,
    poses: list[np.ndarray],
) -> list[float]:
    """ms taken by insert(depth, camera, pose) for each frame."""
    elapsed = []
    for pose, depth in zip(poses, depths, strict=True):
        t0 = time.perf_counter()
        insert(depth, camera, pose)
        elapsed.append(1e3 * (time.perf_counter() - t0))
    return elapsed


def run(frames: int = 30) -> list[dict[str, Any]]:
    import downstream_perception as dp
    from downstream_perception.sim.depth_camera import DepthCamera, circle_poses, room_scene
    from downstream_perception.tsdf_eval import observed_samples, score_mesh

    scene = room_scene()
    poses = circle_poses(frames)
    rows = []
    frames = {}  # image name -> (camera, depths), reused by the OctoMap entry
    for name, cam in (("320x240", DepthCamera()), ("640x480", DepthCamera.vga())):
        depths = [cam.render(scene, T) for T in poses]
        frames[name] = (cam, depths)
        observed = observed_samples(scene, cam, poses, depths)
        pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
        for voxel in (0.02, 0.05):
            config = dp.TsdfConfig()
            config.voxel_size_m = voxel
            tsdf = dp.Tsdf(config)
            integrate_ms = timed_frames(tsdf.integrate_depth, depths, pinhole, poses)
            t0 = time.perf_counter()
            tsdf.update_mesh()
            full_mesh_ms = 1e3 * (time.perf_counter() - t0)
            # One more frame, then only the blocks it changed (and their neighbours) re-mesh.
            tsdf.integrate_depth(depths[0], pinhole, poses[0])
            t0 = time.perf_counter()
            remeshed = tsdf.update_mesh()
            incremental_ms = 1e3 * (time.perf_counter() - t0)
            grid = dp.GridGeometry(int(5.0 / voxel), int(5.0 / voxel), voxel, -2.5, -2.5)
            t0 = time.perf_counter()
            tsdf.slice(grid, 0.05, 1.8)
            slice_ms = 1e3 * (time.perf_counter() - t0)
            # The clearance the nodelet publishes (~slice_distance): the band's 2-D ESDF over the
            # map's whole x-y extent (the grid above is a 5 x 5 m window of it).
            t0 = time.perf_counter()
            band = tsdf.esdf_band_slice(0.05, 1.8, 2.0)
            clearance_ms = 1e3 * (time.perf_counter() - t0)
            band_cells = band["distance"].size
            mesh = tsdf.mesh()
            score = score_mesh(scene, mesh["vertices"], mesh["triangles"], voxel, observed)
            rows.append(
                {
                    "image": name,
                    "voxel_m": voxel,
                    "integrate_median_ms": float(np.median(integrate_ms)),
                    "integrate_p90_ms": float(np.percentile(integrate_ms, 90)),
                    "full_mesh_ms": full_mesh_ms,
                    "incremental_mesh_ms": incremental_ms,
                    "blocks_remeshed": int(remeshed),
                    "slice_ms": slice_ms,
                    "slice_clearance_ms": clearance_ms,
                    "slice_clearance_cells": band_cells,
                    "blocks": int(tsdf.block_count),
                    "memory_mb": tsdf.memory_bytes / 1e6,
                    **score.row(),
                }
            )
    # OctoMap from the same 320x240 frames (every 4th pixel per direction, 5 cm leaves).
    cam, depths = frames["320x240"]
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    tree = dp.OccupancyOctree()
    insert_ms = timed_frames(tree.insert_depth, depths, pinhole, poses)
    rows.append(
        {
            "image": "320x240 / 4 px stride",
            "octomap_insert_median_ms": float(np.median(insert_ms)),
            "octomap_leaves": int(tree.leaf_count),
            "octomap_mb": tree.memory_bytes / 1e6,
        }
    )
    # Free-space carving: whole rays updated, so all the free space in view gets blocks.
    for voxel in (0.02, 0.05):
        config = dp.TsdfConfig()
        config.voxel_size_m = voxel
        config.carve_free_space = True
        tsdf = dp.Tsdf(config)
        carve_ms = timed_frames(tsdf.integrate_depth, depths, pinhole, poses)
        rows.append(
            {
                "image": "320x240 carving",
                "carve_voxel_m": voxel,
                "carve_integrate_median_ms": float(np.median(carve_ms)),
                "carve_blocks": int(tsdf.block_count),
                "carve_mb": tsdf.memory_bytes / 1e6,
            }
        )
    rows += esdf_rows(scene, poses, frames["320x240"])
    return rows


def esdf_rows(
    scene: Any, poses: list[np.ndarray], camera_and_depths: tuple[Any, list[np.ndarray]]
) -> list[dict[str, Any]]:
    """ESDF at 5 cm on the 320x240 room: esdf_update() after every frame (the first is full),
    then a full recomputation, each next to the frame's integration time."""
    import downstream_perception as dp

    cam, depths = camera_and_depths
    pinhole = dp.PinholeCamera(cam.fx, cam.fy, cam.cx, cam.cy, cam.width, cam.height)
    rows = []
    for carve in (False, True):
        config = dp.TsdfConfig()
        config.voxel_size_m = 0.05
        config.carve_free_space = carve
        tsdf = dp.Tsdf(config)
        integrate_ms, update_ms, changed = [], [], []
        for pose, depth in zip(poses, depths, strict=True):
            t0 = time.perf_counter()
            tsdf.integrate_depth(depth, pinhole, pose)
            t1 = time.perf_counter()
            stats = tsdf.esdf_update()
            t2 = time.perf_counter()
            integrate_ms.append(1e3 * (t1 - t0))
            update_ms.append(1e3 * (t2 - t1))
            changed.append(stats.voxels_changed)
        full_ms = []
        for _ in range(3):
            t0 = time.perf_counter()
            tsdf.esdf_recompute()
            full_ms.append(1e3 * (time.perf_counter() - t0))
        incremental = update_ms[1:]  # the first update is the full one
        rows.append(
            {
                "esdf_voxel_m": 0.05,
                "esdf_carving": carve,
                "esdf_max_distance_m": tsdf.esdf_config.max_distance_m,
                "esdf_integrate_median_ms": float(np.median(integrate_ms)),
                "esdf_update_median_ms": float(np.median(incremental)),
                "esdf_update_p90_ms": float(np.percentile(incremental, 90)),
                "esdf_update_max_ms": float(np.max(incremental)),
                "esdf_voxels_changed_median": float(np.median(changed[1:])),
                "esdf_full_median_ms": float(np.median(full_ms)),
                "esdf_blocks": int(tsdf.esdf_block_count),
                "esdf_mb": tsdf.esdf_memory_bytes / 1e6,
                "esdf_tsdf_mb": tsdf.memory_bytes / 1e6,
            }
        )
    return rows


def markdown(rows: list[dict[str, Any]]) -> list[str]:
    lines = [
        "## TSDF (simulated room, 30 frames on a circle, truncation 4 voxels, one thread)",
        "",
        "Through the Python binding (it reads float32 depth in place). Open3D 0.19 "
        "single-thread figures from the anchor notes (same scene kind and machine kind): legacy "
        "/ tensor integrate ms (side by side on the same frames: make bench-open3d). "
        "Accuracy: |true SDF| at mesh vertices; ghosts: vertices more than one voxel off every "
        "surface; completeness: observed surface within 2 cm of the mesh. Goal: <= 5 / 10 ms "
        "per frame (320x240 / 640x480, 2 cm), <= 50 ms full re-mesh.",
        "",
        "| image | voxel | integrate ms (p90) | Open3D legacy / tensor ms | full mesh ms | "
        "one-frame re-mesh ms (blocks) | slice + band ESDF ms (its cells) | blocks | MB | "
        "mean / p95 mm | ghosts % | complete |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        if "voxel_m" not in r:
            continue
        ref = OPEN3D_MS.get((r["image"], r["voxel_m"]))
        lines.append(
            f"| {r['image']} | {100 * r['voxel_m']:.0f} cm | {r['integrate_median_ms']:.2f} "
            f"({r['integrate_p90_ms']:.2f}) | {f'{ref[0]} / {ref[1]}' if ref else ''} | "
            f"{r['full_mesh_ms']:.1f} | {r['incremental_mesh_ms']:.1f} ({r['blocks_remeshed']}) | "
            f"{r['slice_ms']:.1f} + {r['slice_clearance_ms']:.1f} "
            f"({r['slice_clearance_cells']:,}) | "
            f"{r['blocks']} | {r['memory_mb']:.1f} | {r['mean_mm']:.2f} / {r['p95_mm']:.2f} | "
            f"{r['ghost_pct']:.3f} | {r['completeness']:.4f} |"
        )
    for r in rows:
        if "octomap_insert_median_ms" in r:
            lines += [
                "",
                f"OctoMap (octomap::OcTree, 5 cm leaves, rays from every 4th pixel of 320x240): "
                f"{r['octomap_insert_median_ms']:.1f} ms per frame, {r['octomap_leaves']} leaves, "
                f"{r['octomap_mb']:.1f} MB.",
            ]
    for r in rows:
        if "carve_voxel_m" in r:
            lines += [
                "",
                f"With `carve_free_space` (whole rays; 320x240, "
                f"{100 * r['carve_voxel_m']:.0f} cm): "
                f"{r['carve_integrate_median_ms']:.1f} ms per frame, {r['carve_blocks']} blocks, "
                f"{r['carve_mb']:.1f} MB.",
            ]
    esdf = [r for r in rows if "esdf_voxel_m" in r]
    if esdf:
        lines += [
            "",
            "ESDF (exact, from the TSDF; 320x240, 5 cm, max distance "
            f"{esdf[0]['esdf_max_distance_m']:.1f} m): esdf_update() after each of the 30 frames "
            "(the first, full, left out), then a full recomputation (median of 3). Goal: "
            "<= 10 ms per incremental update, <= 50 ms full.",
            "",
            "| TSDF | integrate ms | ESDF update ms median / p90 / max | voxels changed per "
            "frame (median) | full ESDF ms | blocks | ESDF MB (TSDF MB) |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in esdf:
            lines.append(
                f"| {'carving' if r['esdf_carving'] else 'band only'} | "
                f"{r['esdf_integrate_median_ms']:.2f} | {r['esdf_update_median_ms']:.2f} / "
                f"{r['esdf_update_p90_ms']:.2f} / {r['esdf_update_max_ms']:.2f} | "
                f"{r['esdf_voxels_changed_median']:.0f} | {r['esdf_full_median_ms']:.2f} | "
                f"{r['esdf_blocks']} | {r['esdf_mb']:.1f} ({r['esdf_tsdf_mb']:.1f}) |"
            )
    lines.append("")
    return lines


if __name__ == "__main__":
    print("\n".join(markdown(run())))
