"""Scores image-mode trackers on the pinhole scenes (sim.image_scene) with motmetrics.

Ground truth per frame: the people in the image whose visible fraction is at least the scene's
`min_visible` (the detector never sees the others). A tracker reports, as SORT and ByteTrack
do, the confirmed tracks that took a detection this frame; motmetrics matches them to the
truth boxes by IoU >= 0.5. Position error (px) is the distance between a reported track's box
centre and the centre of the person it last took a detection of, and velocity error (px/s)
the same for the image velocity; both only where that person's box lies wholly in the image
(a clipped box's centre moves differently from the person's).

Needs motmetrics (in the workspace's venv, .ws/py-venv).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Protocol

import numpy as np

import downstream_perception as dp
from downstream_perception.bytetrack_reference import ByteTrackReference
from downstream_perception.sim.image_scene import ImageFrame, ImageScene, ImageSceneConfig


class ImageTracker(Protocol):
    def __call__(self, frame: ImageFrame) -> dict[str, np.ndarray]:
        """One frame in; reported tracks out: id (K,), box (K, 4), velocity (K, 2) px/s,
        truth_id (K,)."""
        ...


def ours(config: dp.TrackerConfig) -> ImageTracker:
    """The package's tracker (image mode) behind the ImageTracker interface."""
    tracker = dp.Tracker(config)

    def run(frame: ImageFrame) -> dict[str, np.ndarray]:
        tracker.step(frame.stamp, frame.boxes, scores=frame.scores, truth_ids=frame.detection_truth)
        t = tracker.tracks()
        updated = t["state"] == int(dp.TrackState.CONFIRMED)
        half = t["size"][updated] / 2.0
        centre = t["position"][updated]
        return {
            "id": t["id"][updated].astype(np.int64),
            "box": np.hstack([centre - half, centre + half]),
            "velocity": t["velocity"][updated],
            "truth_id": t["truth_id"][updated],
        }

    return run


def bytetrack(rate_hz: float) -> ImageTracker:
    reference = ByteTrackReference(rate_hz)

    def run(frame: ImageFrame) -> dict[str, np.ndarray]:
        return reference.step(frame.boxes, frame.scores, frame.detection_truth)

    return run


@dataclass
class Score:
    mota: float
    idf1: float
    switches: int
    false_positives: int
    misses: int
    position_error_px: float  # mean over reported tracks on unclipped people
    velocity_error_pxps: float  # mean, likewise
    us_per_frame: float  # the tracker's step, median


def _xywh(boxes: np.ndarray) -> np.ndarray:
    return np.column_stack([boxes[:, :2], boxes[:, 2:] - boxes[:, :2]])


def score(
    scene: ImageSceneConfig, make_tracker: Callable[[], ImageTracker], frames: int = 300
) -> Score:
    import motmetrics as mm

    sim = ImageScene(scene)
    tracker = make_tracker()
    acc = mm.MOTAccumulator(auto_id=True)
    position_errors: list[np.ndarray] = []
    velocity_errors: list[np.ndarray] = []
    step_us: list[float] = []
    for _ in range(frames):
        f = sim.step()
        t0 = time.perf_counter()
        out = tracker(f)
        step_us.append((time.perf_counter() - t0) * 1e6)
        truth = f.in_image & (f.visible_fraction >= scene.min_visible)
        acc.update(
            f.truth_ids[truth],
            out["id"],
            mm.distances.iou_matrix(_xywh(f.truth_boxes[truth]), _xywh(out["box"]), max_iou=0.5),
        )
        person = out["truth_id"]
        whole = np.zeros(len(person), dtype=bool)
        real = person >= 0
        whole[real] = f.in_image[person[real]] & ~f.clipped[person[real]]
        centre = 0.5 * (out["box"][whole, :2] + out["box"][whole, 2:])
        truth_box = f.truth_boxes[person[whole]]
        truth_centre = 0.5 * (truth_box[:, :2] + truth_box[:, 2:])
        position_errors.append(np.linalg.norm(centre - truth_centre, axis=1))
        velocity_errors.append(
            np.linalg.norm(out["velocity"][whole] - f.truth_velocity[person[whole]], axis=1)
        )
    names = ["mota", "idf1", "num_switches", "num_false_positives", "num_misses"]
    m = mm.metrics.create().compute(acc, metrics=names, name="s").iloc[0]
    return Score(
        mota=float(m["mota"]),
        idf1=float(m["idf1"]),
        switches=int(m["num_switches"]),
        false_positives=int(m["num_false_positives"]),
        misses=int(m["num_misses"]),
        position_error_px=float(np.mean(np.concatenate(position_errors))),
        velocity_error_pxps=float(np.mean(np.concatenate(velocity_errors))),
        us_per_frame=float(np.median(step_us)),
    )


def image_defaults() -> dp.TrackerConfig:
    """Image mode's documented defaults (TrackerConfig::defaultsFor)."""
    return dp.TrackerConfig.defaults_for(dp.TrackerConfig.Mode.IMAGE)
