"""pytest: the tracker on simulated scenes, scored with motmetrics (MOTA, IDF1, ID switches).

Scene (sim.objects): 30 people-like objects in a 30 m square, 10 Hz, wandering headings (paths
cross), 0.1 m noise, 5 % missed detections, occlusion gaps of 3-15 frames, one clutter detection
per frame, 10 % of true detections with a low score. Scored two ways, as in the anchor notes:
"visible" (ground truth only while visible, confirmed tracks only) and "all" (occluded objects
count; coasting tracks are reported, which is what a planner wants).
The anchors (abewley/sort and ByteTrack tuned on a comparable scene, N = 30): MOTA 0.88 / IDF1
0.80-0.82 / 32-73 ID switches per 30 s visible, MOTA 0.75 all. Seeds 0-2 have been the scoring
seeds since the scene was written; docs/tracker.md also reports seeds 0-10.
"""

from __future__ import annotations

import numpy as np
import pytest

import downstream_perception as dp
from downstream_perception.sim import ObjectScene, SceneConfig

mm = pytest.importorskip("motmetrics", reason="PyPI motmetrics (make deps installs it)")


def score(seed: int, config: dp.TrackerConfig, frames: int = 300) -> dict[str, float]:
    scene = ObjectScene(SceneConfig(seed=seed))
    tracker = dp.Tracker(config)
    visible = mm.MOTAccumulator(auto_id=True)
    everything = mm.MOTAccumulator(auto_id=True)
    for _ in range(frames):
        f = scene.step()
        tracker.step(f.stamp, f.positions, scores=f.scores)
        t = tracker.tracks()
        confirmed = t["state"] == 1
        reported = t["state"] != 0
        visible.update(
            f.truth_ids[f.visible],
            t["id"][confirmed],
            mm.distances.norm2squared_matrix(
                f.truth_positions[f.visible], t["position"][confirmed], max_d2=0.5**2
            ),
        )
        everything.update(
            f.truth_ids,
            t["id"][reported],
            mm.distances.norm2squared_matrix(
                f.truth_positions, t["position"][reported], max_d2=0.5**2
            ),
        )
    metrics = mm.metrics.create()
    names = ["mota", "idf1", "num_switches"]
    v = metrics.compute(visible, metrics=names, name="v").iloc[0]
    a = metrics.compute(everything, metrics=names, name="a").iloc[0]
    return {
        "mota": float(v["mota"]),
        "idf1": float(v["idf1"]),
        "switches": float(v["num_switches"]),
        "mota_all": float(a["mota"]),
        "idf1_all": float(a["idf1"]),
    }


def test_tracker_defaults_meet_the_goals_on_the_simulated_scene() -> None:
    results = [score(seed, dp.TrackerConfig()) for seed in range(3)]
    mean = {k: float(np.mean([r[k] for r in results])) for k in results[0]}
    print(mean)  # shown with pytest -s
    # Issue 4's goals, with the defaults (no tuning for the scene): MOTA >= 0.90, IDF1 >= 0.90,
    # <= 10 ID switches per 30 s (visible objects), MOTA >= 0.85 with occluded objects counted.
    assert mean["mota"] >= 0.90
    assert mean["idf1"] >= 0.90
    assert mean["switches"] <= 10
    assert mean["mota_all"] >= 0.85


def test_second_pass_pays_off() -> None:
    # ByteTrack's idea on this scene (10 % of true detections have a low score): without the
    # second pass those frames are misses (measured MOTA 0.84 instead of 0.93 on seed 1).
    base = score(1, dp.TrackerConfig())
    no_second = dp.TrackerConfig()
    no_second.second_pass = False
    without = score(1, no_second)
    assert without["mota"] < base["mota"]
    assert without["idf1_all"] <= base["idf1_all"]


def test_scene_generator_is_reproducible_and_has_ground_truth() -> None:
    a = ObjectScene(SceneConfig(seed=3, num_objects=5))
    b = ObjectScene(SceneConfig(seed=3, num_objects=5))
    for _ in range(50):
        fa, fb = a.step(), b.step()
        np.testing.assert_array_equal(fa.positions, fb.positions)
        assert np.all(np.abs(fa.truth_positions) <= 15.0 + 1e-9)
        truth = fa.detection_truth
        real = truth >= 0
        # Every true detection lies near its object (noise 0.1 m: within 0.6 m = 6 sigma).
        errors = np.linalg.norm(fa.positions[real] - fa.truth_positions[truth[real]], axis=1)
        assert np.all(errors < 0.6)
        assert not np.any(np.isin(truth[real], fa.truth_ids[~fa.visible]))
