"""pytest: the tracking core through the bindings: the lesson's golden numbers, the assignment
against brute force, and the tracker on a noisy scene scored by an independent computation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import downstream_perception as dp


def test_iou_nms_mask_and_gate_golden_numbers() -> None:
    assert dp.iou((10, 10, 60, 60), (30, 30, 80, 80)) == pytest.approx(900 / 4100)
    assert round(dp.iou((10, 10, 60, 60), (30, 30, 80, 80)), 3) == 0.220
    assert dp.iou((0, 0, 4, 3), (2, 1, 6, 4)) == pytest.approx(0.2)
    assert dp.iou((0, 0, 1, 1), (2, 2, 3, 3)) == 0.0
    boxes = np.array([[0, 0, 100, 100], [20, 0, 120, 100], [60, 0, 160, 100], [80, 0, 180, 100]])
    assert dp.nms(boxes, np.array([0.95, 0.90, 0.75, 0.70]), 0.5).tolist() == [0, 2]
    pallet = np.zeros((4, 4), dtype=np.uint8)
    pallet[0, :] = 1
    pallet[:, 0] = 1
    assert dp.mask_iou(np.ones((4, 4), dtype=np.uint8), pallet) == pytest.approx(7 / 16)
    assert dp.chi_square_quantile(2, 0.99) == pytest.approx(9.21, abs=5e-3)
    with pytest.raises(ValueError):
        dp.nms(boxes[:, :3], np.ones(4))


def brute_force(cost: np.ndarray) -> tuple[int, float]:
    """Most pairs, then least cost, over every injective partial map rows -> columns."""
    rows, cols = cost.shape
    best = (-1, 0.0)

    def search(r: int, used: frozenset[int], pairs: int, total: float) -> None:
        nonlocal best
        if r == rows:
            if pairs > best[0] or (pairs == best[0] and total < best[1] - 1e-9):
                best = (pairs, total)
            return
        search(r + 1, used, pairs, total)
        for c in range(cols):
            if c not in used and np.isfinite(cost[r, c]):
                search(r + 1, used | {c}, pairs + 1, total + cost[r, c])

    search(0, frozenset(), 0, 0.0)
    return best


def test_assignment_matches_brute_force() -> None:
    rng = np.random.default_rng(2)
    for _ in range(100):
        rows, cols = (int(v) for v in rng.integers(1, 6, size=2))
        cost = rng.uniform(0, 10, size=(rows, cols))
        cost[rng.random((rows, cols)) < 0.3] = np.inf
        pairs_expected, cost_expected = brute_force(cost)
        got = dp.solve_assignment(cost)
        pairs = [(r, c) for r, c in enumerate(got) if c >= 0]
        assert len({c for _, c in pairs}) == len(pairs)
        assert all(np.isfinite(cost[r, c]) for r, c in pairs)
        assert len(pairs) == pairs_expected
        assert sum(cost[r, c] for r, c in pairs) == pytest.approx(cost_expected)


def test_assignment_with_a_cost_limit_takes_one_good_pair_over_two_poor_ones() -> None:
    # Issue 21: ByteTrack's lapjv(cost_limit=L) minimises the sum of (cost - L); the default
    # maximises the pairs first.
    cost = np.array([[0.15, 0.65], [0.5, np.inf]])
    assert dp.solve_assignment(cost) == [1, 0]
    assert dp.solve_assignment(cost, unmatched_pair_cost=0.7) == [0, -1]
    assert dp.solve_assignment(cost, unmatched_pair_cost=0.15) == [-1, -1]  # nothing below L


def test_image_defaults_do_not_maximize_matches() -> None:
    # A person (left track) next to a coasting neighbour (right track, IoU 0.43); the frame holds
    # the person's box and a false positive 60 px below it. Maximising the pairs hands the
    # person to the coasting track; the image default keeps it with its own.
    def outcome(maximize: bool) -> tuple[bool, bool]:
        config = dp.TrackerConfig.defaults_for(dp.TrackerConfig.Mode.IMAGE)
        config.maximize_matches = maximize
        tracker = dp.Tracker(config)
        pair = np.array([[100.0, 100.0, 150.0, 250.0], [120.0, 100.0, 170.0, 250.0]])
        for k in range(25):
            tracker.step(k / 25.0, pair, scores=np.full(2, 0.9))
        left, right = (int(i) for i in tracker.last_assignment())
        tracker.step(1.0, pair[:1], scores=np.array([0.9]))
        boxes = np.vstack([pair[:1], [[100.0, 160.0, 150.0, 310.0]]])
        tracker.step(1.04, boxes, scores=np.array([0.9, 0.6]))
        person, false_positive = (int(i) for i in tracker.last_assignment())
        return person == left, person == right and false_positive == left

    assert not dp.TrackerConfig.defaults_for(dp.TrackerConfig.Mode.IMAGE).maximize_matches
    assert dp.TrackerConfig().maximize_matches  # metric / member default: unchanged
    assert outcome(maximize=False) == (True, False)
    assert outcome(maximize=True) == (False, True)


def test_tracker_keeps_ids_through_noise_misses_and_gaps() -> None:
    """Five objects in lanes 2 m apart at different speeds, 10 Hz, sigma 0.1 m, 90 % detection,
    one 1 s gap each (occlusion)."""
    rng = np.random.default_rng(4)
    start = np.stack([rng.uniform(-5, 5, size=5), 2.0 * np.arange(5)], axis=1)
    velocity = np.stack([rng.uniform(-1.5, 1.5, size=5), rng.uniform(-0.1, 0.1, size=5)], axis=1)
    tracker = dp.Tracker(dp.TrackerConfig())
    switches = 0
    for k in range(150):
        t = 0.1 * k
        truth = start + velocity * t
        seen = rng.random(5) < 0.9
        seen &= ~((k >= 50 + 10 * np.arange(5)) & (k < 60 + 10 * np.arange(5)))  # gaps
        ids = np.flatnonzero(seen)
        positions = truth[ids] + rng.normal(0, 0.1, size=(len(ids), 2))
        stats = tracker.step(t, positions, scores=np.full(len(ids), 0.9), truth_ids=ids)
        switches += stats.id_switches
    tracks = tracker.tracks()
    confirmed = tracks["state"] != 0
    assert switches == 0
    assert int(confirmed.sum()) == 5
    # Each track's velocity matches its object's within the filter's own uncertainty (an honest
    # covariance): squared Mahalanobis error under the 99.9 % chi-square gate.
    errors = tracks["velocity"][confirmed] - velocity[tracks["truth_id"][confirmed]]
    cov = tracks["velocity_cov"][confirmed]
    d2 = np.einsum("ni,nij,nj->n", errors, np.linalg.inv(cov), errors)
    assert np.all(d2 < dp.chi_square_quantile(2, 0.999)), d2
    assert np.all(np.linalg.norm(errors, axis=1) < 0.3)
    assert np.all(np.linalg.eigvalsh(tracks["position_cov"]) > 0)


def test_tracker_rejects_bad_shapes_and_counts_bad_values() -> None:
    tracker = dp.Tracker()
    with pytest.raises(ValueError):
        tracker.step(0.0, np.zeros((3, 3)))
    stats = tracker.step(0.0, np.array([[math.nan, 0.0], [1.0, 1.0]]))
    assert stats.detections_rejected_invalid == 1
    config = dp.TrackerConfig()
    config.min_hits = 0
    with pytest.raises(ValueError):
        dp.Tracker(config)


def test_tracker_counts_out_of_range_and_negative_detections() -> None:
    # Issue 17 item 8: an image box at 1e308 px made the covariance infinite; negative sizes and
    # positions of 1e30 m were accepted silently.
    config = dp.TrackerConfig()
    config.mode = dp.TrackerConfig.Mode.IMAGE
    tracker = dp.Tracker(config)
    boxes = np.array([[0.0, 0.0, 1e308, 1e308], [10.0, 10.0, 60.0, 90.0]])
    for k in range(4):
        stats = tracker.step(0.1 * k, boxes)
        assert stats.detections_rejected_out_of_range == 1
        assert stats.detections_rejected_invalid == 0
    tracks = tracker.tracks()
    assert len(tracks["id"]) == 1
    assert np.isfinite(tracks["position_cov"]).all() and np.isfinite(tracks["velocity_cov"]).all()
    assert dp.TrackerConfig.MAX_BOX_COORDINATE_PX == 1e6

    metric = dp.Tracker()
    too_far = -2.0 * dp.TrackerConfig.MAX_POSITION_M
    stats = metric.step(0.0, np.array([[1e30, 0.0], [1.0, 2.0], [too_far, 0.0]]))
    assert stats.detections_rejected_out_of_range == 2
    assert len(metric.tracks()["id"]) == 1


def test_tracker_carries_metric_sizes_and_counts_unmatched_detections() -> None:
    # Issue 21 defect 5: step() had no sizes argument, so tracks()["size"] was always 0 in
    # metric mode although the C++ detection carries a size; item 7: unmatched_outside_gate.
    config = dp.TrackerConfig()
    config.min_hits = 1
    tracker = dp.Tracker(config)
    positions = np.array([[0.0, 0.0], [10.0, 0.0]])
    sizes = np.array([[0.6, 0.4], [4.5, 1.8]])
    stats = tracker.step(0.0, positions, sizes=sizes)
    assert stats.unmatched_outside_gate == 2  # no track yet: both start one
    stats = tracker.step(0.1, positions + 0.05, sizes=sizes * 1.1)
    assert stats.unmatched_outside_gate == 0
    np.testing.assert_allclose(tracker.tracks()["size"], sizes * 1.1)
    with pytest.raises(ValueError):
        tracker.step(0.2, positions, sizes=sizes[:1])
    image = dp.TrackerConfig()
    image.mode = dp.TrackerConfig.Mode.IMAGE
    with pytest.raises(ValueError):  # a box carries its size
        dp.Tracker(image).step(0.0, np.array([[0.0, 0.0, 10.0, 10.0]]), sizes=np.ones((1, 2)))


def test_tracks_can_leave_out_tentative_tracks() -> None:
    # Issue 21 item 7: a consumer that reports only established tracks filtered by hand.
    tracker = dp.Tracker(dp.TrackerConfig())  # min_hits 3: one detection is a tentative track
    tracker.step(0.0, np.array([[0.0, 0.0]]))
    assert tracker.tracks()["state"].tolist() == [0]
    established = tracker.tracks(include_tentative=False)
    assert established["id"].shape == (0,) and established["position"].shape == (0, 2)
    for k in (1, 2):
        tracker.step(0.1 * k, np.array([[0.0, 0.0]]))
    assert tracker.tracks(include_tentative=False)["state"].tolist() == [1]


def state_of(tracker: dp.Tracker, detection: int) -> int:
    """State of the track that took `detection` in the last step."""
    track_id = int(tracker.last_assignment()[detection])
    tracks = tracker.tracks()
    return int(tracks["state"][tracks["id"] == track_id][0])


@pytest.mark.parametrize("mode", ["METRIC", "IMAGE"])
def test_start_confirmation_through_the_binding(mode: str) -> None:
    # Issue 21: ByteTrack activates the tracks of its first frame at once (score >= its
    # track_thresh + 0.1); confirm_at_start does the same for the first step after construction
    # or reset(), later births wait min_hits.
    config = dp.TrackerConfig.defaults_for(getattr(dp.TrackerConfig.Mode, mode))
    config.min_hits = 3
    config.confirm_at_start = True
    config.start_confirm_score = 0.7
    if mode == "IMAGE":
        first = np.array([[100.0, 100.0, 140.0, 200.0], [300.0, 100.0, 340.0, 200.0]])
        later = np.vstack([first, [[500.0, 100.0, 540.0, 200.0]]])
    else:
        first = np.array([[0.0, 0.0], [5.0, 0.0]])
        later = np.vstack([first, [[10.0, 0.0]]])
    confirmed, tentative = int(dp.TrackState.CONFIRMED), int(dp.TrackState.TENTATIVE)
    tracker = dp.Tracker(config)
    stats = tracker.step(0.0, first, scores=np.array([0.7, 0.65]))  # at and below the score
    assert stats.confirmed == 1
    assert [state_of(tracker, 0), state_of(tracker, 1)] == [confirmed, tentative]
    tracker.step(0.04, later, scores=np.full(3, 0.9))
    assert state_of(tracker, 2) == tentative  # born in the second frame
    tracker.reset()  # re-arms the rule
    tracker.step(1.0, first[:1], scores=np.array([0.9]))
    assert state_of(tracker, 0) == confirmed
    config.confirm_at_start = False
    plain = dp.Tracker(config)
    plain.step(0.0, first[:1], scores=np.array([0.9]))
    assert state_of(plain, 0) == tentative
    config.start_confirm_score = 1.5
    with pytest.raises(ValueError):
        dp.Tracker(config)
