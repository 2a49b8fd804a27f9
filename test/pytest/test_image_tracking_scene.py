"""pytest: the tracker in image mode on the pinhole scenes (sim.image_scene), scored with
motmetrics (IoU >= 0.5), against a ByteTrack-style reference (bytetrack_reference).

Two scene types (street: 10 people at 30 fps, crowd: 16 people at 25 fps with a weaker
detector), three seeds each. Seeds 10-12 are held out: the image-mode defaults were chosen on
seeds 0-7 (docs/tracker.md, "Tracking core"). The floors are the lowest per-scene means measured
on these seeds less a margin for the scene's seed-to-seed spread; the comparison with the
reference is on the same detections.
"""

from __future__ import annotations

import numpy as np
import pytest

from downstream_perception.image_tracking_eval import Score, bytetrack, image_defaults, ours, score
from downstream_perception.sim.image_scene import IMAGE_SCENES

pytest.importorskip("motmetrics", reason="PyPI motmetrics (make deps installs it)")
pytest.importorskip("scipy", reason="the reference tracker's assignment")

SEEDS = (10, 11, 12)


def mean(scores: list[Score], field: str) -> float:
    return float(np.mean([getattr(s, field) for s in scores]))


@pytest.fixture(scope="module")
def results() -> dict[str, dict[str, list[Score]]]:
    out: dict[str, dict[str, list[Score]]] = {}
    for name, make in IMAGE_SCENES.items():
        configs = [make(seed) for seed in SEEDS]
        out[name] = {
            "ours": [score(c, lambda: ours(image_defaults())) for c in configs],
            "bytetrack": [score(c, lambda c=c: bytetrack(c.rate_hz)) for c in configs],
        }
        for tracker, scores in out[name].items():
            print(  # shown with pytest -s
                name,
                tracker,
                {f: round(mean(scores, f), 3) for f in ("mota", "idf1", "switches")},
                {
                    f: round(mean(scores, f), 1)
                    for f in ("position_error_px", "velocity_error_pxps")
                },
            )
    return out


# Per scene: MOTA, IDF1 floors and a ceiling on ID switches per 300 frames (mean of the seeds).
# Measured 2026-12-04 with the IMAGE defaults: street 0.798 / 0.850 / 6.3, crowd 0.661 / 0.576 /
# 38.3. The street's IDF1 floor fails with maximize_matches true (0.810: a coasting track took a
# person's detection while the person's track took a false positive, seed 11).
FLOORS = {"street": (0.77, 0.82, 10.0), "crowd": (0.63, 0.55, 45.0)}


@pytest.mark.parametrize("name", sorted(IMAGE_SCENES))
def test_image_defaults_reach_the_floors(results, name: str) -> None:  # type: ignore[no-untyped-def]
    mota, idf1, switches = FLOORS[name]
    scores = results[name]["ours"]
    assert mean(scores, "mota") >= mota
    assert mean(scores, "idf1") >= idf1
    assert mean(scores, "switches") <= switches


@pytest.mark.parametrize("name", sorted(IMAGE_SCENES))
def test_image_defaults_match_the_bytetrack_reference(results, name: str) -> None:  # type: ignore[no-untyped-def]
    ours_scores, reference = results[name]["ours"], results[name]["bytetrack"]
    # At least the reference's MOTA and IDF1 (0.01 for the seeds' spread), and a velocity no
    # worse: both filters see the same boxes.
    assert mean(ours_scores, "mota") >= mean(reference, "mota") - 0.01
    assert mean(ours_scores, "idf1") >= mean(reference, "idf1") - 0.01
    assert mean(ours_scores, "velocity_error_pxps") <= mean(reference, "velocity_error_pxps")


def test_velocity_is_in_pixels_per_second(results) -> None:  # type: ignore[no-untyped-def]
    # People walk at 0.6-1.6 m/s; at 500 px focal length and 3-16 m that is roughly 20-270 px/s
    # sideways. A velocity in px per frame, or a sign error, would be off by far more than the
    # errors allowed here (a few tens of px/s, on a few px of box noise per frame).
    for name in IMAGE_SCENES:
        for s in results[name]["ours"]:
            assert s.velocity_error_pxps < 25.0
            assert s.position_error_px < 5.0
