"""Analytic 2-D worlds for the lidar simulator: line segments (walls, box edges), round pillars and
moving round objects. Units: metres, seconds, radians (REP-103: x forward, y left, yaw CCW)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Warehouse aisle (the demo world): x from 0 to 20 m, shelves at y = +-1.5 m.
AISLE_LENGTH_M = 20.0
AISLE_HALF_WIDTH_M = 1.5
DOORWAY_HALF_WIDTH_M = 0.5  # gap in the end wall at x = 20, centred on y = 0
PALLET_CENTRE = (8.0, 1.2)  # 0.6 m x 0.6 m box against the left shelf
PALLET_HALF_M = 0.3
PILLARS = ((12.0, -1.25, 0.15), (16.0, 1.25, 0.15))  # (x, y, radius)
PERSON_RADIUS_M = 0.25
PERSON_PATH = ((4.0, 10.0, -1.3), (8.0, 10.0, 1.3))  # (t_s, x, y): crosses the aisle, then leaves


@dataclass
class MovingCircle:
    """A round object moving along a piecewise-linear path; absent outside the path's times."""

    radius: float
    waypoints: np.ndarray  # (P, 3) rows (t_s, x, y), t increasing

    def position(self, t: float) -> tuple[float, float] | None:
        times = self.waypoints[:, 0]
        if t < times[0] or t > times[-1]:
            return None
        x = float(np.interp(t, times, self.waypoints[:, 1]))
        y = float(np.interp(t, times, self.waypoints[:, 2]))
        return x, y


def box_segments(cx: float, cy: float, half_x: float, half_y: float) -> np.ndarray:
    """The four edges (4, 4) of an axis-aligned box, rows (x0, y0, x1, y1)."""
    x0, x1, y0, y1 = cx - half_x, cx + half_x, cy - half_y, cy + half_y
    return np.array(
        [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]], dtype=np.float64
    )


@dataclass
class MovingBox:
    """An axis-aligned box (a forklift, a cart) moving along a piecewise-linear path; absent
    outside the path's times."""

    half_x: float
    half_y: float
    waypoints: np.ndarray  # (P, 3) rows (t_s, x, y), t increasing

    def position(self, t: float) -> tuple[float, float] | None:
        return MovingCircle(0.0, self.waypoints).position(t)


@dataclass
class SeenObject:
    """What an ideal detector reports of a mover at one instant (world frame)."""

    truth_id: int
    label: str
    x: float
    y: float
    size_x: float
    size_y: float


@dataclass
class World:
    segments: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))  # (M, 4) x0 y0 x1 y1
    circles: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # (K, 3) cx cy r
    movers: list[MovingCircle] = field(default_factory=list)
    boxes: list[MovingBox] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)  # per mover, then per box; default "object"

    def segments_at(self, t: float) -> np.ndarray:
        """Static segments plus the edges of the moving boxes present at time t, (M', 4)."""
        present = [box_segments(*p, b.half_x, b.half_y) for b in self.boxes if (p := b.position(t))]
        return np.vstack([self.segments, *present]) if present else self.segments

    def objects_at(self, t: float) -> list[SeenObject]:
        """Every mover and moving box present at time t; truth ids count movers, then boxes."""
        seen = []
        for k, m in enumerate([*self.movers, *self.boxes]):
            p = m.position(t)
            if p is None:
                continue
            label = self.labels[k] if k < len(self.labels) else "object"
            if isinstance(m, MovingCircle):
                size_x = size_y = 2.0 * m.radius
            else:
                size_x, size_y = 2.0 * m.half_x, 2.0 * m.half_y
            seen.append(SeenObject(k, label, p[0], p[1], size_x, size_y))
        return seen

    def circles_at(self, t: float) -> np.ndarray:
        """Static circles plus the movers present at time t, (K', 3)."""
        present = [(*p, m.radius) for m in self.movers if (p := m.position(t)) is not None]
        if not present:
            return self.circles
        return np.vstack([self.circles, np.asarray(present, dtype=np.float64)])

    def raycast(
        self, origin: np.ndarray, angles: np.ndarray, max_range: float, t: float = 0.0
    ) -> np.ndarray:
        """Distance along each world-frame angle (N,) to the first obstacle; inf if none within
        max_range. Vectorised over beams x obstacles."""
        ox, oy = float(origin[0]), float(origin[1])
        dx = np.cos(angles)[:, None]
        dy = np.sin(angles)[:, None]
        best = np.full(angles.shape, np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            segments = self.segments_at(t)
            if len(segments):
                s = segments
                ex = (s[:, 2] - s[:, 0])[None, :]
                ey = (s[:, 3] - s[:, 1])[None, :]
                wx = (s[:, 0] - ox)[None, :]
                wy = (s[:, 1] - oy)[None, :]
                denom = dx * ey - dy * ex  # cross(d, e)
                t_ray = (wx * ey - wy * ex) / denom
                u_seg = (wx * dy - wy * dx) / denom
                ok = (np.abs(denom) > 1e-12) & (t_ray > 1e-9) & (u_seg >= 0.0) & (u_seg <= 1.0)
                best = np.minimum(best, np.where(ok, t_ray, np.inf).min(axis=1))
            circles = self.circles_at(t)
            if len(circles):
                fx = (ox - circles[:, 0])[None, :]
                fy = (oy - circles[:, 1])[None, :]
                r2 = (circles[:, 2] ** 2)[None, :]
                b = fx * dx + fy * dy
                c = fx * fx + fy * fy - r2
                disc = b * b - c
                t_hit = -b - np.sqrt(np.maximum(disc, 0.0))
                # A sensor inside a circle sees through it (c < 0): no hit from that circle.
                ok = (disc >= 0.0) & (c > 0.0) & (t_hit > 1e-9)
                best = np.minimum(best, np.where(ok, t_hit, np.inf).min(axis=1))
        best[best > max_range] = np.inf
        return best

    def occupied_cells(
        self, origin_x: float, origin_y: float, resolution: float, size_x: int, size_y: int
    ) -> np.ndarray:
        """Ground truth: (size_y, size_x) bool, True where a static obstacle's outline passes
        through the cell. Segments are sampled every resolution / 8 and floored; circles mark
        the cells whose square meets the circle's rim band (the sensor sees the rim only)."""
        occ = np.zeros((size_y, size_x), dtype=bool)

        def mark(px: np.ndarray, py: np.ndarray) -> None:
            ix = np.floor((px - origin_x) / resolution).astype(np.int64)
            iy = np.floor((py - origin_y) / resolution).astype(np.int64)
            ok = (ix >= 0) & (iy >= 0) & (ix < size_x) & (iy < size_y)
            occ[iy[ok], ix[ok]] = True

        step = resolution / 8.0
        for x0, y0, x1, y1 in self.segments:
            n = max(2, int(np.hypot(x1 - x0, y1 - y0) / step) + 1)
            s = np.linspace(0.0, 1.0, n)
            mark(x0 + s * (x1 - x0), y0 + s * (y1 - y0))
        for cx, cy, r in self.circles:
            n = max(16, int(2 * np.pi * r / step))
            a = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
            mark(cx + r * np.cos(a), cy + r * np.sin(a))
        return occ


def warehouse_aisle() -> World:
    """A 20 m x 3 m aisle: shelves at y = +-1.5 from x = 0 to 20, an end wall at x = 20 with a
    1 m doorway (nothing behind it), the x = 0 end open, a pallet against the left shelf at x = 8,
    two pillars, and a person crossing at x = 10 between t = 4 s and 8 s."""
    length, half = AISLE_LENGTH_M, AISLE_HALF_WIDTH_M
    door = DOORWAY_HALF_WIDTH_M
    segments = [
        [0.0, half, length, half],
        [0.0, -half, length, -half],
        [length, half, length, door],
        [length, -door, length, -half],
    ]
    pallet = box_segments(PALLET_CENTRE[0], PALLET_CENTRE[1], PALLET_HALF_M, PALLET_HALF_M)
    return World(
        segments=np.vstack([np.asarray(segments, dtype=np.float64), pallet]),
        circles=np.asarray(PILLARS, dtype=np.float64),
        movers=[MovingCircle(PERSON_RADIUS_M, np.asarray(PERSON_PATH, dtype=np.float64))],
    )


def aisle_traffic() -> World:
    """The warehouse aisle (without its crossing person) with traffic for the handoff demo: a
    forklift (1.2 m x 0.8 m) driving down the aisle towards x = 0 at 0.7 m/s, one person crossing
    the aisle back and forth at x = 11, another walking up the aisle at 1 m/s. A robot standing
    at x = 2 faces them all."""
    aisle = warehouse_aisle()
    forklift = MovingBox(0.6, 0.4, np.array([[0.0, 17.5, -0.7], [20.0, 3.5, -0.7]]))
    crossing = MovingCircle(
        PERSON_RADIUS_M,
        np.array(
            [
                [0.0, 11.0, 1.2],
                [4.8, 11.0, -1.2],
                [9.6, 11.0, 1.2],
                [14.4, 11.0, -1.2],
                [19.2, 11.0, 1.2],
                [24.0, 11.0, -1.2],
            ]
        ),
    )
    walking = MovingCircle(PERSON_RADIUS_M, np.array([[0.0, 4.5, 0.6], [12.0, 16.5, 0.6]]))
    return World(
        segments=aisle.segments,
        circles=aisle.circles,
        movers=[crossing, walking],
        boxes=[forklift],
        labels=["person", "person", "forklift"],
    )


def open_field() -> World:
    """Nothing at all: every beam is a no-return (+inf)."""
    return World()


WORLDS = {
    "warehouse_aisle": warehouse_aisle,
    "aisle_traffic": aisle_traffic,
    "open_field": open_field,
}
