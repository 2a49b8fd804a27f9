"""A 2-D lidar over a World: Gaussian range noise, dropouts as NaN (invalid, REP-117) and +inf for
no return within range_max."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from downstream_perception.sim.world import World


@dataclass
class LidarConfig:
    num_beams: int = 360
    angle_min: float = -np.pi  # rad, sensor frame
    range_min: float = 0.05  # m
    range_max: float = 30.0  # m
    noise_std_m: float = 0.01  # Gaussian range noise
    dropout_prob: float = 0.0  # fraction of beams returned as NaN
    seed: int = 0

    @property
    def angle_increment(self) -> float:
        """Full circle: angle_max = angle_min + (num_beams - 1) * increment."""
        return 2.0 * np.pi / self.num_beams


class Lidar:
    def __init__(self, config: LidarConfig | None = None) -> None:
        self.config = config or LidarConfig()
        self._rng = np.random.default_rng(self.config.seed)

    def angles(self) -> np.ndarray:
        c = self.config
        return c.angle_min + np.arange(c.num_beams) * c.angle_increment

    def scan(self, world: World, pose: tuple[float, float, float], t: float = 0.0) -> np.ndarray:
        """Ranges (N,) float32 from the sensor pose (x, y, yaw) in the world frame at time t."""
        c = self.config
        x, y, yaw = pose
        true = world.raycast(np.array([x, y]), self.angles() + yaw, c.range_max, t)
        noisy = true + self._rng.normal(0.0, c.noise_std_m, size=true.shape)
        noisy = np.where(np.isfinite(true), np.maximum(noisy, c.range_min), np.inf)
        noisy[noisy > c.range_max] = np.inf
        if c.dropout_prob > 0.0:
            noisy[self._rng.random(true.shape) < c.dropout_prob] = np.nan
        return noisy.astype(np.float32)
