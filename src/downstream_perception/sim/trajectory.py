"""Piecewise-linear robot trajectories (x, y in metres, yaw along the direction of travel)."""

from __future__ import annotations

import numpy as np


class Trajectory:
    def __init__(self, waypoints: np.ndarray) -> None:
        """waypoints: (P, 3) rows (t_s, x, y), t strictly increasing, P >= 2."""
        w = np.asarray(waypoints, dtype=np.float64)
        if w.ndim != 2 or w.shape[1] != 3 or len(w) < 2 or np.any(np.diff(w[:, 0]) <= 0):
            raise ValueError("waypoints must be (P >= 2, 3) rows (t, x, y) with increasing t")
        self.waypoints = w
        d = np.diff(w[:, 1:], axis=0)
        moving = np.hypot(d[:, 0], d[:, 1]) > 1e-12
        yaw = np.arctan2(d[:, 1], d[:, 0])
        for k in range(1, len(yaw)):  # a stop keeps the previous heading
            if not moving[k]:
                yaw[k] = yaw[k - 1]
        self._segment_yaw = yaw

    @property
    def duration(self) -> float:
        return float(self.waypoints[-1, 0] - self.waypoints[0, 0])

    def _segment(self, t: float) -> int:
        k = int(np.searchsorted(self.waypoints[:, 0], t, side="right")) - 1
        return min(max(k, 0), len(self._segment_yaw) - 1)

    def pose(self, t: float) -> tuple[float, float, float]:
        w = self.waypoints
        tc = min(max(t, w[0, 0]), w[-1, 0])
        x = float(np.interp(tc, w[:, 0], w[:, 1]))
        y = float(np.interp(tc, w[:, 0], w[:, 2]))
        return x, y, float(self._segment_yaw[self._segment(tc)])

    def velocity(self, t: float) -> tuple[float, float, float]:
        """(vx, vy, yaw_rate) in the world frame; zero outside the time range."""
        w = self.waypoints
        if t < w[0, 0] or t > w[-1, 0]:
            return 0.0, 0.0, 0.0
        k = self._segment(t)
        dt = w[k + 1, 0] - w[k, 0]
        return (w[k + 1, 1] - w[k, 1]) / dt, (w[k + 1, 2] - w[k, 2]) / dt, 0.0


def aisle_drive(speed_mps: float = 1.0) -> Trajectory:
    """Down the middle of the warehouse aisle (y = 0) from x = 1 to x = 18."""
    if speed_mps <= 0.0:
        raise ValueError("speed_mps must be positive")
    return Trajectory(np.array([[0.0, 1.0, 0.0], [17.0 / speed_mps, 18.0, 0.0]]))


def stand(x: float, y: float, duration_s: float) -> Trajectory:
    """Standing still at (x, y), facing +x, for duration_s."""
    if not duration_s > 0.0:
        raise ValueError("duration_s must be positive")
    return Trajectory(np.array([[0.0, x, y], [duration_s, x, y]]))
