"""pytest: the ByteTrack-style reference (bytetrack_reference) follows the rules it states, so
the comparison in test_image_tracking_scene.py is against what its docstring says."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("scipy", reason="the reference tracker's assignment")

from downstream_perception.bytetrack_reference import (  # noqa: E402
    ByteTrackReference,
    iou_matrix,
    match,
)

NO_TRUTH = np.array([-1])


def box(x: float) -> np.ndarray:
    return np.array([[x, 100.0, x + 40.0, 200.0]])


def test_iou_and_gated_matching() -> None:
    a = np.array([[0.0, 0.0, 10.0, 10.0]])
    b = np.array([[5.0, 0.0, 15.0, 10.0], [20.0, 0.0, 30.0, 10.0]])
    np.testing.assert_allclose(iou_matrix(a, b), [[50.0 / 150.0, 0.0]])
    # The cheaper pair is taken; a pair above the limit never is.
    assert match(np.array([[0.2, 0.1], [0.3, 0.9]]), 0.5) == [(0, 1), (1, 0)]
    assert match(np.array([[0.6]]), 0.5) == []


def test_a_walking_box_keeps_one_id_and_its_velocity() -> None:
    tracker = ByteTrackReference(rate_hz=25.0)
    reported = []
    for k in range(30):
        reported.append(tracker.step(box(100.0 + 2.0 * k), np.array([0.9]), NO_TRUTH))
    # Frame 1 confirms at once; every later frame reports the same id.
    assert all(len(r["id"]) == 1 for r in reported)
    assert len({int(r["id"][0]) for r in reported}) == 1
    assert reported[-1]["velocity"][0, 0] == pytest.approx(50.0, rel=0.1)  # 2 px x 25 fps


def test_low_scores_continue_tracks_but_never_start_them() -> None:
    tracker = ByteTrackReference(rate_hz=25.0)
    tracker.step(box(100.0), np.array([0.9]), NO_TRUTH)
    # A low-score detection (between 0.1 and 0.5) keeps the track reported...
    out = tracker.step(box(101.0), np.array([0.3]), NO_TRUTH)
    assert len(out["id"]) == 1
    # ...but alone, far away, it starts nothing; and 0.55 (< 0.6) is below the birth threshold.
    tracker.step(np.vstack([box(101.0), box(400.0)]), np.array([0.9, 0.3]), -np.ones(2))
    assert len(tracker.tracks) == 1
    tracker.step(np.vstack([box(101.0), box(400.0)]), np.array([0.9, 0.55]), -np.ones(2))
    assert len(tracker.tracks) == 1


def test_a_lost_track_dies_after_the_buffer() -> None:
    tracker = ByteTrackReference(rate_hz=30.0, track_buffer=30)  # 30 frames
    tracker.step(box(100.0), np.array([0.9]), NO_TRUTH)
    for _ in range(30):
        assert not len(tracker.step(np.zeros((0, 4)), np.zeros(0), np.zeros(0, int))["id"])
    assert len(tracker.tracks) == 1  # lost for 30 frames: kept
    tracker.step(np.zeros((0, 4)), np.zeros(0), np.zeros(0, int))
    assert len(tracker.tracks) == 0
