"""People walking on a floor, seen through a pinhole camera: a 2-D box detector's output with
ground truth (pure numpy, seeded).

World frame: x right, y forward (away from the camera), z up; the floor is z = 0. The camera
stands at (0, 0, camera_height_m) looking along +y, pitched down by `pitch_rad`. People are
vertical boxes of human size (0.5 m wide, 1.55-1.95 m tall) walking at 0.6-1.6 m/s with a slowly
wandering heading inside a floor region in front of the camera (reflected at its edges), so
they cross, approach and recede (perspective size change) and hide one another.

Each frame, per person: the projected box (the image bounding box of its eight corners), the
box clipped to the image, the fraction of the clipped box not covered by the boxes of nearer
people (sampled on a grid of points), and the box centre's image velocity (px/s, from the 3-D
velocity through the projection's derivative). The detector sees a person with a probability
that falls with occlusion (none below `min_visible`), reports a noisy box (noise proportional to
the box height) and a score that drops with occlusion, and adds false positives of person-like
size with low-to-middle scores.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class ImageSceneConfig:
    num_people: int = 12
    rate_hz: float = 25.0
    width_px: int = 640
    height_px: int = 480
    focal_px: float = 500.0  # fx = fy; principal point at the image centre
    camera_height_m: float = 2.5
    pitch_rad: float = 0.2  # downwards
    floor_x_m: tuple[float, float] = (-7.0, 7.0)  # region people walk in
    floor_y_m: tuple[float, float] = (3.0, 16.0)
    person_width_m: float = 0.5
    person_height_m: tuple[float, float] = (1.55, 1.95)
    speed_mps: tuple[float, float] = (0.6, 1.6)
    turn_std_radps: float = 0.4  # heading random walk, rad/sqrt(s)
    miss_prob: float = 0.08  # of a fully visible person
    min_visible: float = 0.3  # visible fraction below which a person is never detected
    min_in_image: float = 0.3  # fraction of the projected box inside the image to count at all
    box_noise: float = 0.03  # std of each box edge, in box heights
    false_positives_per_frame: float = 0.5  # Poisson mean
    seed: int = 0


@dataclass
class ImageFrame:
    stamp: float
    truth_ids: np.ndarray  # (N,) every person, in the image or not
    truth_boxes: np.ndarray  # (N, 4) x_min, y_min, x_max, y_max, clipped to the image (px)
    projected_boxes: np.ndarray  # (N, 4) not clipped (px)
    truth_velocity: np.ndarray  # (N, 2) image velocity of the projected box centre (px/s)
    in_image: np.ndarray  # (N,) bool: in front of the camera, min_in_image of its box inside
    clipped: np.ndarray  # (N,) bool: the projected box reaches beyond the image
    visible_fraction: np.ndarray  # (N,) of the clipped box not hidden by nearer people
    depth_m: np.ndarray  # (N,) along the optical axis
    boxes: np.ndarray  # (M, 4) detections (px)
    scores: np.ndarray  # (M,)
    detection_truth: np.ndarray  # (M,) person id, -1 for a false positive


# Points per box (columns x rows) on which occlusion is sampled.
_OCCLUSION_GRID = (8, 16)


class PinholeCamera:
    """Projection of world points (x right, y forward, z up) into pixels."""

    def __init__(self, config: ImageSceneConfig) -> None:
        c = config
        self.focal = c.focal_px
        self.center = np.array([c.width_px / 2.0, c.height_px / 2.0])
        self.origin = np.array([0.0, 0.0, c.camera_height_m])
        s, k = np.sin(c.pitch_rad), np.cos(c.pitch_rad)
        # Rows: the optical axes x (right), y (down), z (forward) in world coordinates.
        self.rotation = np.array([[1.0, 0.0, 0.0], [0.0, -s, -k], [0.0, k, -s]])

    def to_camera(self, points: np.ndarray) -> np.ndarray:
        """(..., 3) world -> (..., 3) optical frame."""
        return (points - self.origin) @ self.rotation.T

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(..., 3) world -> pixels (..., 2) and depth (...,) along the optical axis."""
        p = self.to_camera(points)
        depth = p[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            uv = self.focal * p[..., :2] / depth[..., None] + self.center
        return uv, depth


def person_corners(feet: np.ndarray, width_m: float, heights: np.ndarray) -> np.ndarray:
    """(N, 8, 3) corners of upright boxes standing at feet (N, 2), `width_m` square."""
    half = width_m / 2.0
    dx = np.array([-1, 1, -1, 1, -1, 1, -1, 1]) * half
    dy = np.array([-1, -1, 1, 1, -1, -1, 1, 1]) * half
    up = np.array([0, 0, 0, 0, 1, 1, 1, 1], dtype=float)
    return np.stack(
        [
            feet[:, None, 0] + dx,
            feet[:, None, 1] + dy,
            heights[:, None] * up,
        ],
        axis=2,
    )


def project_boxes(
    camera: PinholeCamera, feet: np.ndarray, width_m: float, heights: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Image bounding boxes (N, 4) of the people and their centre depths (N,)."""
    uv, _ = camera.project(person_corners(feet, width_m, heights))
    boxes = np.concatenate([uv.min(axis=1), uv.max(axis=1)], axis=1)
    centre = np.column_stack([feet, heights / 2.0])
    _, depth = camera.project(centre)
    return boxes, depth


def box_centres(boxes: np.ndarray) -> np.ndarray:
    return 0.5 * (boxes[:, :2] + boxes[:, 2:])


def visible_fractions(boxes: np.ndarray, depth: np.ndarray, present: np.ndarray) -> np.ndarray:
    """Fraction of each present box not covered by a nearer present box (grid-sampled)."""
    n = len(boxes)
    if n == 0:
        return np.zeros(0)
    cols, rows = _OCCLUSION_GRID
    fx = (np.arange(cols) + 0.5) / cols
    fy = (np.arange(rows) + 0.5) / rows
    gx, gy = np.meshgrid(fx, fy)
    size = boxes[:, 2:] - boxes[:, :2]
    px = boxes[:, None, 0] + gx.ravel()[None, :] * size[:, None, 0]  # (N, K)
    py = boxes[:, None, 1] + gy.ravel()[None, :] * size[:, None, 1]
    inside = (
        (px[:, :, None] >= boxes[None, None, :, 0])
        & (px[:, :, None] <= boxes[None, None, :, 2])
        & (py[:, :, None] >= boxes[None, None, :, 1])
        & (py[:, :, None] <= boxes[None, None, :, 3])
    )  # (N, K, N): sample k of box i inside box j
    nearer = present[None, :] & (depth[None, :] < depth[:, None])  # (N, N): j in front of i
    covered = np.any(inside & nearer[:, None, :], axis=2)
    visible = 1.0 - covered.mean(axis=1)
    return np.where(present, visible, 0.0)


class ImageScene:
    """Iterate to get one ImageFrame per call of step()."""

    def __init__(self, config: ImageSceneConfig | None = None) -> None:
        self.config = config or ImageSceneConfig()
        c = self.config
        self.rng = np.random.default_rng(c.seed)
        self.camera = PinholeCamera(c)
        n = c.num_people
        self.feet = np.column_stack(
            [self.rng.uniform(*c.floor_x_m, size=n), self.rng.uniform(*c.floor_y_m, size=n)]
        )
        self.heights = self.rng.uniform(*c.person_height_m, size=n)
        self.heading = self.rng.uniform(-np.pi, np.pi, size=n)
        self.speed = self.rng.uniform(*c.speed_mps, size=n)
        self.frame = 0

    def velocity(self) -> np.ndarray:
        return self.speed[:, None] * np.column_stack([np.cos(self.heading), np.sin(self.heading)])

    def _walk(self, dt: float) -> None:
        c = self.config
        self.heading += self.rng.normal(0.0, c.turn_std_radps * np.sqrt(dt), size=c.num_people)
        self.feet += self.velocity() * dt
        for axis, (lo, hi) in enumerate((c.floor_x_m, c.floor_y_m)):
            below, above = self.feet[:, axis] < lo, self.feet[:, axis] > hi
            self.feet[below, axis] = 2 * lo - self.feet[below, axis]
            self.feet[above, axis] = 2 * hi - self.feet[above, axis]
            flip = below | above
            if axis == 0:
                self.heading[flip] = np.pi - self.heading[flip]
            else:
                self.heading[flip] = -self.heading[flip]

    def _truth(self) -> dict[str, np.ndarray]:
        c = self.config
        boxes, depth = project_boxes(self.camera, self.feet, c.person_width_m, self.heights)
        # Image velocity of the box centre: the projection's derivative along the 3-D velocity.
        eps = 1e-3
        ahead, _ = project_boxes(
            self.camera, self.feet + eps * self.velocity(), c.person_width_m, self.heights
        )
        velocity = (box_centres(ahead) - box_centres(boxes)) / eps
        limits = np.array([0.0, 0.0, c.width_px, c.height_px])
        clipped_boxes = np.column_stack(
            [
                np.clip(boxes[:, 0], 0, c.width_px),
                np.clip(boxes[:, 1], 0, c.height_px),
                np.clip(boxes[:, 2], 0, c.width_px),
                np.clip(boxes[:, 3], 0, c.height_px),
            ]
        )
        # In the image: in front of the camera with at least min_in_image of its box inside.
        area = np.prod(clipped_boxes[:, 2:] - clipped_boxes[:, :2], axis=1)
        full_area = np.prod(boxes[:, 2:] - boxes[:, :2], axis=1)
        in_image = (depth > 0.1) & (area > c.min_in_image * full_area)
        clipped = in_image & np.any(
            np.column_stack([boxes[:, :2] < limits[:2], boxes[:, 2:] > limits[2:]]), axis=1
        )
        visible = visible_fractions(clipped_boxes, depth, in_image)
        return {
            "boxes": clipped_boxes,
            "projected": boxes,
            "velocity": velocity,
            "in_image": in_image,
            "clipped": clipped,
            "visible": visible,
            "depth": depth,
        }

    def _detect(self, truth: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, rng = self.config, self.rng
        visible = truth["visible"]
        # Detection probability falls linearly from (1 - miss_prob) when fully visible to 0 at
        # min_visible; the score falls with occlusion too (occluded people are the low-score
        # detections ByteTrack's second pass is for).
        ramp = np.clip((visible - c.min_visible) / (1.0 - c.min_visible), 0.0, 1.0)
        detected = truth["in_image"] & (rng.random(c.num_people) < (1.0 - c.miss_prob) * ramp)
        ids = np.flatnonzero(detected)
        boxes = truth["boxes"][ids]
        height = (boxes[:, 3] - boxes[:, 1])[:, None]
        noisy = boxes + rng.normal(0.0, c.box_noise, size=boxes.shape) * height
        scores = np.clip(0.25 + 0.7 * ramp[ids] + rng.normal(0.0, 0.1, size=len(ids)), 0.05, 1.0)
        n_false = rng.poisson(c.false_positives_per_frame)
        h = rng.uniform(40.0, 200.0, size=n_false)
        w = h * rng.uniform(0.3, 0.5, size=n_false)
        x = rng.uniform(0.0, c.width_px - w)
        y = rng.uniform(0.0, c.height_px - h)
        false_boxes = np.column_stack([x, y, x + w, y + h])
        false_scores = rng.uniform(0.1, 0.7, size=n_false)
        out = np.vstack([noisy, false_boxes])
        # A noisy box keeps a positive size (the tracker rejects empty boxes).
        out[:, 2:] = np.maximum(out[:, 2:], out[:, :2] + 1.0)
        return (
            out,
            np.concatenate([scores, false_scores]),
            np.concatenate([ids, -np.ones(n_false, dtype=int)]),
        )

    def step(self) -> ImageFrame:
        dt = 1.0 / self.config.rate_hz
        if self.frame > 0:
            self._walk(dt)
        truth = self._truth()
        boxes, scores, detection_truth = self._detect(truth)
        frame = ImageFrame(
            stamp=self.frame * dt,
            truth_ids=np.arange(self.config.num_people),
            truth_boxes=truth["boxes"],
            projected_boxes=truth["projected"],
            truth_velocity=truth["velocity"],
            in_image=truth["in_image"],
            clipped=truth["clipped"],
            visible_fraction=truth["visible"],
            depth_m=truth["depth"],
            boxes=boxes,
            scores=scores,
            detection_truth=detection_truth,
        )
        self.frame += 1
        return frame


def street_scene(seed: int) -> ImageSceneConfig:
    """Sparse: 10 people, 30 fps, camera 3 m up looking down (little overlap, big size change)."""
    return ImageSceneConfig(
        num_people=10, rate_hz=30.0, camera_height_m=3.0, pitch_rad=0.25, seed=seed
    )


def crowd_scene(seed: int) -> ImageSceneConfig:
    """Dense: 16 people, 25 fps, camera 2 m up (people hide one another often); a weaker
    detector (15 % misses, box edges within 4 % of the height)."""
    return ImageSceneConfig(
        num_people=16,
        rate_hz=25.0,
        miss_prob=0.15,
        box_noise=0.04,
        camera_height_m=2.0,
        pitch_rad=0.12,
        floor_x_m=(-6.0, 6.0),
        floor_y_m=(3.0, 14.0),
        seed=seed,
    )


IMAGE_SCENES = {"street": street_scene, "crowd": crowd_scene}
