"""A yardstick for the image-mode tracker: ByteTrack's association with its published defaults.

Written from the paper's description (Zhang et al., "ByteTrack: Multi-Object Tracking by
Associating Every Detection Box", ECCV 2022) and the defaults of its reference tracker, in
numpy. Only for benchmarks and tests: it is slow (pure Python per track) and takes no part in
the package's nodes.

What it does per frame:
  1. Detections at or above `track_thresh` are "high", those in (`low_thresh`, `track_thresh`)
     "low"; the rest are dropped.
  2. Confirmed tracks, the ones following an object and the lost ones alike, are predicted
     (constant velocity on centre, aspect ratio and height, noise proportional to the height,
     one step per frame) and matched to the high detections on 1 - IoU * score, accepted up
     to 0.8.
  3. Confirmed tracks still following an object that found nothing take low detections on
     1 - IoU, accepted up to 0.5; those still without one become lost.
  4. Unconfirmed tracks (born last frame) take leftover high detections (1 - IoU * score up to
     0.7), are confirmed by it, or are removed.
  5. Leftover high detections at or above `track_thresh + 0.1` start unconfirmed tracks.
  6. A lost track is removed after `track_buffer` frames at 30 fps (scaled to the frame rate);
     of a following and a lost track overlapping by IoU > 0.85 the shorter-lived is removed.
Output: the confirmed tracks that took a detection this frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linear_sum_assignment

# Noise weights of the per-frame Kalman filter (std as a fraction of the box height).
_POSITION_WEIGHT = 1.0 / 20.0
_VELOCITY_WEIGHT = 1.0 / 160.0


def iou_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of boxes (x_min, y_min, x_max, y_max): (N, 4) x (M, 4) -> (N, M)."""
    if len(a) == 0 or len(b) == 0:
        return np.zeros((len(a), len(b)))
    lo = np.maximum(a[:, None, :2], b[None, :, :2])
    hi = np.minimum(a[:, None, 2:], b[None, :, 2:])
    inter = np.prod(np.clip(hi - lo, 0.0, None), axis=2)
    area_a = np.prod(a[:, 2:] - a[:, :2], axis=1)
    area_b = np.prod(b[:, 2:] - b[:, :2], axis=1)
    return inter / np.maximum(area_a[:, None] + area_b[None, :] - inter, 1e-12)


def match(cost: np.ndarray, limit: float) -> list[tuple[int, int]]:
    """Minimum-cost pairs with cost <= limit (pairs above it are never chosen)."""
    if cost.size == 0:
        return []
    blocked = np.where(cost <= limit, cost, limit + 1e3)
    rows, cols = linear_sum_assignment(blocked)
    return [(int(r), int(c)) for r, c in zip(rows, cols, strict=True) if cost[r, c] <= limit]


def _to_xyah(box: np.ndarray) -> np.ndarray:
    w, h = box[2] - box[0], box[3] - box[1]
    return np.array([box[0] + w / 2, box[1] + h / 2, w / h, h])


@dataclass
class _Track:
    mean: np.ndarray  # cx, cy, aspect, h and their per-frame rates
    cov: np.ndarray
    track_id: int
    truth_id: int
    start_frame: int
    last_frame: int
    confirmed: bool = False
    lost: bool = False
    history: list[int] = field(default_factory=list)

    def box(self) -> np.ndarray:
        cx, cy, a, h = self.mean[:4]
        w = a * h
        return np.array([cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2])

    def predict(self) -> None:
        if self.lost:
            self.mean[7] = 0.0  # a lost track keeps its height
        h = self.mean[3]
        q = np.array([_POSITION_WEIGHT * h] * 2 + [1e-2, _POSITION_WEIGHT * h])
        q = np.concatenate([q, [_VELOCITY_WEIGHT * h] * 2 + [1e-5, _VELOCITY_WEIGHT * h]])
        f = np.eye(8)
        f[:4, 4:] = np.eye(4)
        self.mean = f @ self.mean
        self.cov = f @ self.cov @ f.T + np.diag(q**2)

    def correct(self, box: np.ndarray) -> None:
        z = _to_xyah(box)
        h = self.mean[3]
        std = np.array([_POSITION_WEIGHT * h, _POSITION_WEIGHT * h, 1e-1, _POSITION_WEIGHT * h])
        r = np.diag(std**2)
        s = self.cov[:4, :4] + r
        gain = np.linalg.solve(s, self.cov[:4, :]).T
        self.mean = self.mean + gain @ (z - self.mean[:4])
        self.cov = self.cov - gain @ s @ gain.T


class ByteTrackReference:
    """step(boxes, scores, truth_ids) once per frame; returns the reported tracks."""

    def __init__(
        self,
        rate_hz: float,
        track_thresh: float = 0.5,
        low_thresh: float = 0.1,
        match_thresh: float = 0.8,
        track_buffer: int = 30,
    ) -> None:
        self.rate_hz = rate_hz
        self.high = track_thresh
        self.low = low_thresh
        self.birth = track_thresh + 0.1
        self.match_thresh = match_thresh
        self.max_lost = int(rate_hz / 30.0 * track_buffer)
        self.tracks: list[_Track] = []
        self.frame = 0
        self.next_id = 1

    def _new(self, box: np.ndarray, truth: int) -> _Track:
        z = _to_xyah(box)
        h = z[3]
        std = [2 * _POSITION_WEIGHT * h] * 2 + [1e-2, 2 * _POSITION_WEIGHT * h]
        std += [10 * _VELOCITY_WEIGHT * h] * 2 + [1e-5, 10 * _VELOCITY_WEIGHT * h]
        track = _Track(
            np.concatenate([z, np.zeros(4)]),
            np.diag(np.square(std)),
            self.next_id,
            truth,
            self.frame,
            self.frame,
            confirmed=self.frame == 1,
        )
        self.next_id += 1
        return track

    def _take(self, track: _Track, box: np.ndarray, truth: int) -> None:
        track.correct(box)
        track.last_frame = self.frame
        track.truth_id = truth
        track.lost = False
        track.confirmed = True

    def step(
        self, boxes: np.ndarray, scores: np.ndarray, truth_ids: np.ndarray
    ) -> dict[str, np.ndarray]:
        self.frame += 1
        high = np.flatnonzero(scores >= self.high)
        low = np.flatnonzero((scores > self.low) & (scores < self.high))
        confirmed = [t for t in self.tracks if t.confirmed]
        unconfirmed = [t for t in self.tracks if not t.confirmed]
        for t in self.tracks:
            t.predict()

        def cost(tracks: list[_Track], dets: np.ndarray, fuse: bool) -> np.ndarray:
            boxes_t = np.array([t.box() for t in tracks]).reshape(-1, 4)
            overlap = iou_matrix(boxes_t, boxes[dets])
            return 1.0 - overlap * scores[dets][None, :] if fuse else 1.0 - overlap

        left_high = list(high)
        taken: set[int] = set()
        for r, c in match(cost(confirmed, high, True), self.match_thresh):
            self._take(confirmed[r], boxes[high[c]], int(truth_ids[high[c]]))
            taken.add(id(confirmed[r]))
            left_high.remove(high[c])
        following = [t for t in confirmed if id(t) not in taken and not t.lost]
        for r, c in match(cost(following, low, False), 0.5):
            self._take(following[r], boxes[low[c]], int(truth_ids[low[c]]))
            taken.add(id(following[r]))
        for t in following:
            if id(t) not in taken:
                t.lost = True
        left = np.array(left_high, dtype=int)
        kept_new: list[_Track] = []
        for r, c in match(cost(unconfirmed, left, True), 0.7):
            self._take(unconfirmed[r], boxes[left[c]], int(truth_ids[left[c]]))
            kept_new.append(unconfirmed[r])
            left_high.remove(left[c])
        born = [
            self._new(boxes[j], int(truth_ids[j])) for j in left_high if scores[j] >= self.birth
        ]
        self.tracks = [
            t for t in confirmed if not (t.lost and self.frame - t.last_frame > self.max_lost)
        ]
        self._drop_duplicates()
        self.tracks += kept_new + born
        return self.reported()

    def _drop_duplicates(self) -> None:
        following = [t for t in self.tracks if not t.lost]
        lost = [t for t in self.tracks if t.lost]
        if not following or not lost:
            return
        overlap = iou_matrix(
            np.array([t.box() for t in following]), np.array([t.box() for t in lost])
        )
        gone: set[int] = set()
        for i, k in zip(*np.nonzero(overlap > 0.85), strict=True):
            a, b = following[i], lost[k]
            shorter = a if a.last_frame - a.start_frame < b.last_frame - b.start_frame else b
            gone.add(id(shorter))
        self.tracks = [t for t in self.tracks if id(t) not in gone]

    def reported(self) -> dict[str, np.ndarray]:
        out = [t for t in self.tracks if t.confirmed and not t.lost and t.last_frame == self.frame]
        return {
            "id": np.array([t.track_id for t in out], dtype=np.int64),
            "box": np.array([t.box() for t in out]).reshape(-1, 4),
            "velocity": np.array([t.mean[4:6] * self.rate_hz for t in out]).reshape(-1, 2),
            "truth_id": np.array([t.truth_id for t in out], dtype=int),
        }
