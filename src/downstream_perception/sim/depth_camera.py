"""Analytic 3-D scenes and a pinhole depth camera that ray-casts them (pure numpy).

A scene is a room (axis-aligned box seen from inside) holding boxes, spheres and vertical
cylinders. ``render`` returns z-depth images in the ROS optical convention (z forward, x right,
y down; float32 metres, NaN where nothing is hit within range), ``signed_distance`` the exact
distance to the nearest surface (positive in free space), and ``surface_samples`` points on the
surfaces for completeness checks. Optional Gaussian depth noise and pose noise.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Box:
    center: tuple[float, float, float]
    half_extents: tuple[float, float, float]


@dataclass
class Sphere:
    center: tuple[float, float, float]
    radius: float


@dataclass
class Cylinder:
    """Vertical (along z) cylinder from z_min to z_max."""

    center_xy: tuple[float, float]
    radius: float
    z_min: float
    z_max: float


@dataclass
class Scene3D:
    room_min: tuple[float, float, float] = (-2.0, -2.0, 0.0)
    room_max: tuple[float, float, float] = (2.0, 2.0, 3.0)
    boxes: list[Box] = field(default_factory=list)
    spheres: list[Sphere] = field(default_factory=list)
    cylinders: list[Cylinder] = field(default_factory=list)

    def signed_distance(self, p: np.ndarray) -> np.ndarray:
        """Exact signed distance (m) of points (N, 3) to the nearest surface; > 0 in free space."""
        p = np.asarray(p, dtype=float)
        lo, hi = np.asarray(self.room_min), np.asarray(self.room_max)
        d = np.min(np.concatenate([p - lo, hi - p], axis=1), axis=1)  # inside the room
        for b in self.boxes:
            d = np.minimum(d, box_signed_distance(p, b))
        for s in self.spheres:
            d = np.minimum(d, np.linalg.norm(p - np.asarray(s.center), axis=1) - s.radius)
        for c in self.cylinders:
            radial = np.linalg.norm(p[:, :2] - np.asarray(c.center_xy), axis=1) - c.radius
            half = 0.5 * (c.z_max - c.z_min)
            vertical = np.abs(p[:, 2] - 0.5 * (c.z_max + c.z_min)) - half
            outside = np.linalg.norm(
                np.stack([np.maximum(radial, 0), np.maximum(vertical, 0)]), axis=0
            )
            d = np.minimum(d, outside + np.minimum(np.maximum(radial, vertical), 0.0))
        return d

    def intersect(self, origins: np.ndarray, directions: np.ndarray) -> np.ndarray:
        """Ray parameter t of the first hit of rays o + t d (N, 3 each; d need not be unit)."""
        t = _room_exit(origins, directions, np.asarray(self.room_min), np.asarray(self.room_max))
        for b in self.boxes:
            c, h = np.asarray(b.center), np.asarray(b.half_extents)
            t = np.minimum(t, _box_entry(origins, directions, c - h, c + h))
        for s in self.spheres:
            t = np.minimum(t, _sphere_entry(origins, directions, np.asarray(s.center), s.radius))
        for c in self.cylinders:
            t = np.minimum(t, _cylinder_entry(origins, directions, c))
        return t

    def surface_samples(self, spacing_m: float) -> np.ndarray:
        """Points on every surface, about `spacing_m` apart (for completeness)."""
        pts = [_box_surface(self.room_min, self.room_max, spacing_m)]
        for b in self.boxes:
            c, h = np.asarray(b.center), np.asarray(b.half_extents)
            pts.append(_box_surface(tuple(c - h), tuple(c + h), spacing_m))
        for s in self.spheres:
            n = max(8, int(4 * np.pi * s.radius**2 / spacing_m**2))
            k = np.arange(n) + 0.5  # Fibonacci sphere
            phi = np.arccos(1 - 2 * k / n)
            theta = np.pi * (1 + 5**0.5) * k
            u = np.stack([np.cos(theta) * np.sin(phi), np.sin(theta) * np.sin(phi), np.cos(phi)], 1)
            pts.append(np.asarray(s.center) + s.radius * u)
        for c in self.cylinders:
            na = max(8, int(2 * np.pi * c.radius / spacing_m))
            nz = max(2, int((c.z_max - c.z_min) / spacing_m))
            a, z = np.meshgrid(
                np.linspace(0, 2 * np.pi, na, endpoint=False), np.linspace(c.z_min, c.z_max, nz)
            )
            x = c.center_xy[0] + c.radius * np.cos(a)
            y = c.center_xy[1] + c.radius * np.sin(a)
            pts.append(np.stack([x.ravel(), y.ravel(), z.ravel()], 1))
        return np.vstack(pts)


def room_scene(offset: tuple[float, float, float] = (0.0073, -0.0041, 0.0029)) -> Scene3D:
    """The anchors' test room: 4 x 4 x 3 m with a box, a floating sphere and a thin pole, plus a
    table top (a thin slab at 0.75 m) for the costmap slice.

    Everything is shifted by `offset` (m) so that no surface lies on a plane of voxel centres:
    such a surface puts D = 0 exactly at voxel centres, a best case for accuracy (vertices land
    on the lattice) and a bad case for marching cubes' completeness, and real surfaces are not
    aligned with the map's lattice. offset = (0, 0, 0) gives the aligned room.
    """
    o = np.asarray(offset, dtype=float)

    def at(*p: float) -> tuple[float, float, float]:
        q = np.asarray(p) + o
        return (float(q[0]), float(q[1]), float(q[2]))

    return Scene3D(
        room_min=at(-2.0, -2.0, 0.0),
        room_max=at(2.0, 2.0, 3.0),
        boxes=[
            Box(at(0.8, 0.6, 0.35), (0.3, 0.25, 0.35)),
            Box(at(-0.8, 0.7, 0.74), (0.4, 0.3, 0.02)),  # table top
        ],
        spheres=[Sphere(at(-0.5, -0.6, 1.2), 0.3)],
        cylinders=[Cylinder(at(0.4, -0.9, 0.0)[:2], 0.03, o[2], 2.0 + o[2])],
    )


CORRIDOR_PERIOD_M = 4.0  # the corridor repeats the room's furniture every 4 m along x


def corridor_scene(
    copies: range = range(-1, 5), period_m: float = CORRIDOR_PERIOD_M, length_m: float = 1000.0
) -> Scene3D:
    """An endless corridor for long camera paths (soaks): the room's cross-section (y, z) open
    along x to +-length_m, its furniture repeated every `period_m` (copy k shifted by k *
    period_m). Seen from x in [0, period_m) looking ahead (+x, within 90 degrees) with a 10 m
    range, copies -1 .. 4 are all an endless corridor would show: the others are out of range or
    behind the camera. So a frame seen from x + period_m equals the one seen from x, and a
    simulator can render one period and replay it shifted."""
    room = room_scene()
    lo, hi = room.room_min, room.room_max
    scene = Scene3D(room_min=(-length_m, lo[1], lo[2]), room_max=(length_m, hi[1], hi[2]))
    for k in copies:
        dx = k * period_m
        scene.boxes += [
            Box((b.center[0] + dx, b.center[1], b.center[2]), b.half_extents) for b in room.boxes
        ]
        scene.spheres += [
            Sphere((s.center[0] + dx, s.center[1], s.center[2]), s.radius) for s in room.spheres
        ]
        scene.cylinders += [
            Cylinder((c.center_xy[0] + dx, c.center_xy[1]), c.radius, c.z_min, c.z_max)
            for c in room.cylinders
        ]
    return scene


def corridor_poses(
    n: int,
    period_m: float = CORRIDOR_PERIOD_M,
    height_m: float = 1.5,
    sway_rad: float = 0.5,
) -> list[np.ndarray]:
    """n camera poses walking one period down the corridor's middle (y = 0): x = k * period_m /
    n, looking ahead and down at the furniture, yaw swaying +-sway_rad once per period. Pose k +
    n is pose k shifted by period_m along x (see corridor_scene)."""
    if n < 1 or not period_m > 0.0 or not abs(sway_rad) < 1.2:
        raise ValueError("corridor_poses: n >= 1, period_m > 0 and |sway_rad| < 1.2 rad")
    poses = []
    for k in range(n):
        x = k * period_m / n
        yaw = sway_rad * np.sin(2.0 * np.pi * k / n)
        eye = np.array([x, 0.0, height_m])
        target = eye + np.array([2.0 * np.cos(yaw), 2.0 * np.sin(yaw), -0.9])
        poses.append(look_at(eye, target))
    return poses


@dataclass
class DepthCamera:
    width: int = 320
    height: int = 240
    fx: float = 262.5
    fy: float = 262.5
    cx: float = 159.5
    cy: float = 119.5
    max_range_m: float = 10.0

    @staticmethod
    def vga() -> DepthCamera:
        return DepthCamera(640, 480, 525.0, 525.0, 319.5, 239.5)

    def rays(self) -> np.ndarray:
        """(H*W, 3) rays (x/z, y/z, 1) in the optical frame, row-major."""
        u, v = np.meshgrid(np.arange(self.width), np.arange(self.height))
        x = (u - self.cx) / self.fx
        y = (v - self.cy) / self.fy
        return np.stack([x.ravel(), y.ravel(), np.ones(x.size)], 1)

    def render(
        self,
        scene: Scene3D,
        T_map_camera: np.ndarray,
        depth_noise_m: float = 0.0,
        rng: np.random.Generator | None = None,
    ) -> np.ndarray:
        """z-depth image (H, W) float32 m; NaN where nothing is hit within max_range_m."""
        rays = self.rays()
        directions = rays @ T_map_camera[:3, :3].T
        origins = np.broadcast_to(T_map_camera[:3, 3], directions.shape)
        t = scene.intersect(origins, directions)  # rays have z = 1: t is the depth
        if depth_noise_m > 0.0:
            t = t + (rng or np.random.default_rng()).normal(0.0, depth_noise_m, t.shape)
        t = np.where((t > 0) & (t * np.linalg.norm(rays, axis=1) <= self.max_range_m), t, np.nan)
        return t.reshape(self.height, self.width).astype(np.float32)


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray | None = None) -> np.ndarray:
    """4 x 4 T_map_camera of an optical frame at `eye` looking at `target` (z forward, y down)."""
    up = np.array([0.0, 0.0, 1.0]) if up is None else up
    z = target - eye
    z = z / np.linalg.norm(z)
    x = np.cross(z, up)
    x = x / np.linalg.norm(x)
    y = np.cross(z, x)
    T = np.eye(4)
    T[:3, :3] = np.stack([x, y, z], 1)
    T[:3, 3] = eye
    return T


def circle_poses(
    n: int = 30,
    radius_m: float = 1.4,
    height_m: float = 1.5,
    target: tuple[float, float, float] = (0.0, 0.0, 0.6),
) -> list[np.ndarray]:
    """n camera poses on a horizontal circle, all looking at `target`."""
    poses = []
    for a in np.linspace(0.0, 2 * np.pi, n, endpoint=False):
        eye = np.array([radius_m * np.cos(a), radius_m * np.sin(a), height_m])
        poses.append(look_at(eye, np.asarray(target)))
    return poses


def perturb_pose(
    T: np.ndarray, translation_std_m: float, rotation_std_rad: float, rng: np.random.Generator
) -> np.ndarray:
    """T with Gaussian translation and small-angle rotation noise (pose-drift simulation)."""
    w = rng.normal(0.0, rotation_std_rad, 3)
    angle = np.linalg.norm(w)
    K = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    R = (
        np.eye(3) + K
        if angle < 1e-12
        else np.eye(3) + np.sin(angle) / angle * K + (1 - np.cos(angle)) / angle**2 * K @ K
    )
    out = T.copy()
    out[:3, :3] = R @ T[:3, :3]
    out[:3, 3] = T[:3, 3] + rng.normal(0.0, translation_std_m, 3)
    return out


# ------------------------------------------------------------------ ray / shape helpers
def box_signed_distance(p: np.ndarray, box: Box) -> np.ndarray:
    """Exact signed distance (m) of points (N, 3) to an axis-aligned box; < 0 inside it."""
    q = np.abs(p - np.asarray(box.center)) - np.asarray(box.half_extents)
    return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(np.max(q, axis=1), 0.0)


def _slabs(
    o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        t1 = (lo - o) * inv
        t2 = (hi - o) * inv
    t_near = np.nanmax(np.minimum(t1, t2), axis=1)
    t_far = np.nanmin(np.maximum(t1, t2), axis=1)
    return t_near, t_far


def _box_entry(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    t_near, t_far = _slabs(o, d, lo, hi)
    return np.where((t_near <= t_far) & (t_near > 0), t_near, np.inf)


def _room_exit(o: np.ndarray, d: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    _, t_far = _slabs(o, d, lo, hi)
    return np.where(t_far > 0, t_far, np.inf)


def _sphere_entry(o: np.ndarray, d: np.ndarray, c: np.ndarray, r: float) -> np.ndarray:
    oc = o - c
    a = np.einsum("ij,ij->i", d, d)
    b = 2.0 * np.einsum("ij,ij->i", oc, d)
    cc = np.einsum("ij,ij->i", oc, oc) - r * r
    disc = b * b - 4 * a * cc
    with np.errstate(invalid="ignore"):
        t = (-b - np.sqrt(disc)) / (2 * a)
    return np.where((disc >= 0) & (t > 0), t, np.inf)


def _cylinder_entry(o: np.ndarray, d: np.ndarray, c: Cylinder) -> np.ndarray:
    oc = o[:, :2] - np.asarray(c.center_xy)
    dd = d[:, :2]
    a = np.einsum("ij,ij->i", dd, dd)
    b = 2.0 * np.einsum("ij,ij->i", oc, dd)
    cc = np.einsum("ij,ij->i", oc, oc) - c.radius**2
    disc = b * b - 4 * a * cc
    with np.errstate(invalid="ignore", divide="ignore"):
        t = (-b - np.sqrt(disc)) / (2 * a)
    z = o[:, 2] + t * d[:, 2]
    side = np.where((disc >= 0) & (t > 0) & (z >= c.z_min) & (z <= c.z_max), t, np.inf)
    # Caps (the top one is what a camera above sees).
    caps = np.full(len(o), np.inf)
    for zc in (c.z_min, c.z_max):
        with np.errstate(invalid="ignore", divide="ignore"):
            tc = (zc - o[:, 2]) / d[:, 2]
        inside = np.linalg.norm(oc + tc[:, None] * dd, axis=1) <= c.radius
        caps = np.where(inside & (tc > 0), np.minimum(caps, tc), caps)
    return np.minimum(side, caps)


def _box_surface(lo: tuple[float, ...], hi: tuple[float, ...], spacing: float) -> np.ndarray:
    lo_a, hi_a = np.asarray(lo, float), np.asarray(hi, float)
    pts = []
    for axis in range(3):
        a, b = [k for k in range(3) if k != axis]
        ga = np.linspace(lo_a[a], hi_a[a], max(2, int((hi_a[a] - lo_a[a]) / spacing) + 1))
        gb = np.linspace(lo_a[b], hi_a[b], max(2, int((hi_a[b] - lo_a[b]) / spacing) + 1))
        A, B = np.meshgrid(ga, gb)
        for value in (lo_a[axis], hi_a[axis]):
            p = np.zeros((A.size, 3))
            p[:, axis] = value
            p[:, a] = A.ravel()
            p[:, b] = B.ravel()
            pts.append(p)
    return np.vstack(pts)
