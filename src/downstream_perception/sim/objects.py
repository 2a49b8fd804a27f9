"""Moving objects and what a detector reports about them (pure numpy), with ground truth.

A square area holds N objects moving at walking speed with a slowly wandering heading (they
cross each other's paths), reflected at the walls. Each frame every object is detected with
probability ``1 - miss_prob`` unless it is in an occlusion gap (3-15 frames, started at random),
with Gaussian position noise and a score; clutter detections appear at random places. Every
detection carries the id of the object it came from (-1 for clutter), so trackers can be scored.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class SceneConfig:
    num_objects: int = 30
    area_m: float = 30.0  # side of the square, m
    rate_hz: float = 10.0
    speed_mps: tuple[float, float] = (0.5, 1.5)
    turn_std_radps: float = 0.3  # heading random walk, rad/sqrt(s)
    noise_std_m: float = 0.1
    miss_prob: float = 0.05
    gap_start_prob: float = 0.01  # per object and frame
    gap_frames: tuple[int, int] = (3, 15)
    clutter_per_frame: float = 1.0  # Poisson mean
    low_score_prob: float = 0.1  # true detections reported with a low score (0.15..0.5)
    seed: int = 0


@dataclass
class Frame:
    stamp: float
    truth_ids: np.ndarray  # (N,) ids of every object (visible or not)
    truth_positions: np.ndarray  # (N, 2) m
    visible: np.ndarray  # (N,) bool: not in an occlusion gap
    positions: np.ndarray  # (M, 2) detections, m
    scores: np.ndarray  # (M,)
    detection_truth: np.ndarray  # (M,) object id or -1 for clutter


class ObjectScene:
    """Iterate to get one Frame per call of step()."""

    def __init__(self, config: SceneConfig | None = None) -> None:
        self.config = config or SceneConfig()
        c = self.config
        self.rng = np.random.default_rng(c.seed)
        half = c.area_m / 2.0
        self.position = self.rng.uniform(-half, half, size=(c.num_objects, 2))
        self.heading = self.rng.uniform(-np.pi, np.pi, size=c.num_objects)
        self.speed = self.rng.uniform(*c.speed_mps, size=c.num_objects)
        self.gap_left = np.zeros(c.num_objects, dtype=int)
        self.frame = 0

    def step(self) -> Frame:
        c = self.config
        dt = 1.0 / c.rate_hz
        rng = self.rng
        half = c.area_m / 2.0
        if self.frame > 0:
            self.heading += rng.normal(0.0, c.turn_std_radps * np.sqrt(dt), size=c.num_objects)
            velocity = self.speed[:, None] * np.stack(
                [np.cos(self.heading), np.sin(self.heading)], 1
            )
            self.position += velocity * dt
            # Reflect at the walls (the heading mirrors with the position).
            for axis in range(2):
                out = np.abs(self.position[:, axis]) > half
                self.position[out, axis] = np.sign(self.position[out, axis]) * (
                    2 * half - np.abs(self.position[out, axis])
                )
                if axis == 0:
                    self.heading[out] = np.pi - self.heading[out]
                else:
                    self.heading[out] = -self.heading[out]
        # Occlusion gaps.
        self.gap_left = np.maximum(self.gap_left - 1, 0)
        start = (self.gap_left == 0) & (rng.random(c.num_objects) < c.gap_start_prob)
        self.gap_left[start] = rng.integers(c.gap_frames[0], c.gap_frames[1] + 1, size=start.sum())
        visible = self.gap_left == 0
        detected = visible & (rng.random(c.num_objects) >= c.miss_prob)
        ids = np.flatnonzero(detected)
        positions = self.position[ids] + rng.normal(0.0, c.noise_std_m, size=(len(ids), 2))
        scores = rng.uniform(0.5, 1.0, size=len(ids))
        low = rng.random(len(ids)) < c.low_score_prob
        scores[low] = rng.uniform(0.15, 0.5, size=low.sum())
        n_clutter = rng.poisson(c.clutter_per_frame)
        clutter = rng.uniform(-half, half, size=(n_clutter, 2))
        clutter_scores = rng.uniform(0.1, 0.7, size=n_clutter)
        frame = Frame(
            stamp=self.frame * dt,
            truth_ids=np.arange(c.num_objects),
            truth_positions=self.position.copy(),
            visible=visible,
            positions=np.vstack([positions, clutter]),
            scores=np.concatenate([scores, clutter_scores]),
            detection_truth=np.concatenate([ids, -np.ones(n_clutter, dtype=int)]),
        )
        self.frame += 1
        return frame
