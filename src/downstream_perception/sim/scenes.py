"""Analytic 3-D scenes with camera paths for accuracy benchmarks over several scenes and lattice
offsets (bench/bench_tsdf_accuracy.py).

Each builder returns a scene and its camera poses (T_map_camera) with every axis-aligned plane on
a multiple of 2 cm and 5 cm, so offset (0, 0, 0) puts them on planes of voxel centres of either
lattice (the aligned case); `accuracy_scene(name, offset)` shifts scene and cameras together by
`offset` (m), so the images stay the same and only the map's lattice moves under them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from downstream_perception.sim.depth_camera import (
    Box,
    Cylinder,
    Scene3D,
    Sphere,
    circle_poses,
    look_at,
    room_scene,
)

ScenePoses = tuple[Scene3D, list[np.ndarray]]


def shift_scene(scene: Scene3D, offset: tuple[float, float, float]) -> Scene3D:
    """`scene` with every surface moved by `offset` (m)."""
    dx, dy, dz = (float(v) for v in offset)

    def at(p: tuple[float, float, float]) -> tuple[float, float, float]:
        return (p[0] + dx, p[1] + dy, p[2] + dz)

    return Scene3D(
        room_min=at(scene.room_min),
        room_max=at(scene.room_max),
        boxes=[Box(at(b.center), b.half_extents) for b in scene.boxes],
        spheres=[Sphere(at(s.center), s.radius) for s in scene.spheres],
        cylinders=[
            Cylinder(
                (c.center_xy[0] + dx, c.center_xy[1] + dy), c.radius, c.z_min + dz, c.z_max + dz
            )
            for c in scene.cylinders
        ],
    )


def shift_poses(poses: list[np.ndarray], offset: tuple[float, float, float]) -> list[np.ndarray]:
    """Camera poses moved by `offset` (m), orientation kept."""
    out = []
    for T in poses:
        moved = np.array(T, dtype=np.float64)
        moved[:3, 3] += np.asarray(offset, dtype=float)
        out.append(moved)
    return out


def room(frames: int) -> ScenePoses:
    """The anchors' room (sim.depth_camera.room_scene, aligned): 4 x 4 x 3 m, a box, a table
    top, a floating sphere, a thin pole; cameras on a circle looking at its middle."""
    return room_scene((0.0, 0.0, 0.0)), circle_poses(frames)


def furniture(frames: int) -> ScenePoses:
    """A 5 x 4 x 2.6 m room furnished differently: a tall cabinet against a wall, a low bench, a
    shelf board, a ball on the floor, a floor-to-ceiling post (10 cm) and a thin rod (3 cm,
    thinner than two voxels); cameras on a wider, lower circle."""
    scene = Scene3D(
        room_min=(-2.5, -2.0, 0.0),
        room_max=(2.5, 2.0, 2.6),
        boxes=[
            Box((-2.2, 1.2, 0.9), (0.3, 0.5, 0.9)),  # cabinet against the -x wall
            Box((0.9, -0.8, 0.2), (0.6, 0.2, 0.2)),  # bench
            Box((1.0, 1.7, 1.1), (0.5, 0.2, 0.02)),  # shelf board against the +y wall
        ],
        spheres=[Sphere((0.6, 0.9, 0.25), 0.25)],  # a ball resting on the floor
        cylinders=[
            Cylinder((-0.6, -1.0), 0.05, 0.0, 2.6),  # post, floor to ceiling
            Cylinder((1.1, 0.4), 0.015, 0.0, 1.2),  # rod
        ],
    )
    return scene, circle_poses(frames, radius_m=1.7, height_m=1.3, target=(0.0, 0.0, 0.5))


def clutter(frames: int, seed: int = 3) -> ScenePoses:
    """A 4 x 4 x 2.5 m room with a 3 x 3 grid of small objects (boxes, balls, posts of random
    sizes and places within their 0.7 m cells, fixed seed): many depth edges at short range."""
    rng = np.random.default_rng(seed)
    scene = Scene3D(room_min=(-2.0, -2.0, 0.0), room_max=(2.0, 2.0, 2.5))
    cell = 0.7
    for i in range(3):
        for j in range(3):
            cx, cy = (i - 1) * cell, (j - 1) * cell
            size = float(rng.uniform(0.08, 0.22))  # half size or radius, m
            jx, jy = rng.uniform(-1, 1, 2) * (0.5 * cell - size - 0.02)
            x, y = round(cx + jx, 2), round(cy + jy, 2)
            kind = (i * 3 + j) % 3
            if kind == 0:
                h = float(rng.uniform(0.1, 0.5))
                scene.boxes.append(Box((x, y, h), (size, float(rng.uniform(0.08, size)), h)))
            elif kind == 1:
                z = float(rng.choice([size, 0.8]))  # on the floor or floating
                scene.spheres.append(Sphere((x, y, z), size))
            else:
                top = float(rng.uniform(0.6, 1.8))
                scene.cylinders.append(Cylinder((x, y), 0.3 * size, 0.0, top))
    return scene, circle_poses(frames, radius_m=1.6, height_m=1.6, target=(0.0, 0.0, 0.4))


def corridor(frames: int) -> ScenePoses:
    """A 10 m x 2.4 m x 2.6 m corridor with boxes and posts along both walls and a ball; the
    camera walks 4 m down its middle looking ahead and down, yaw swaying, the end wall 5-9 m off
    (far depths: a pixel spans more than a 2 cm voxel there)."""
    scene = Scene3D(
        room_min=(-1.0, -1.2, 0.0),
        room_max=(9.0, 1.2, 2.6),
        boxes=[
            Box((1.5, 0.9, 0.4), (0.3, 0.3, 0.4)),
            Box((3.2, -0.95, 0.6), (0.4, 0.25, 0.6)),
            Box((5.5, 0.85, 0.3), (0.5, 0.35, 0.3)),
            Box((7.0, -0.9, 0.9), (0.25, 0.3, 0.02)),  # a wall shelf
        ],
        spheres=[Sphere((4.4, 0.6, 1.5), 0.2)],
        cylinders=[Cylinder((2.4, -0.5), 0.04, 0.0, 2.6), Cylinder((6.2, 0.3), 0.06, 0.0, 1.6)],
    )
    poses = []
    for k in range(frames):
        x = 4.0 * k / frames
        yaw = 0.4 * np.sin(2.0 * np.pi * k / frames)
        eye = np.array([x, 0.0, 1.5])
        poses.append(look_at(eye, eye + np.array([2.0 * np.cos(yaw), 2.0 * np.sin(yaw), -0.8])))
    return scene, poses


ACCURACY_SCENES: dict[str, Callable[[int], ScenePoses]] = {
    "room": room,
    "furniture": furniture,
    "clutter": clutter,
    "corridor": corridor,
}


def accuracy_scene(
    name: str, offset: tuple[float, float, float] = (0.0, 0.0, 0.0), frames: int = 30
) -> ScenePoses:
    """Scene `name` (ACCURACY_SCENES) and its `frames` camera poses, both moved by `offset` (m)."""
    scene, poses = ACCURACY_SCENES[name](frames)
    return shift_scene(scene, offset), shift_poses(poses, offset)
