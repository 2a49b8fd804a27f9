"""pytest: the pinhole image scene (sim.image_scene): projection, perspective, occlusion,
image velocity and the detector's rules, each against a closed-form oracle."""

from __future__ import annotations

import numpy as np
import pytest

from downstream_perception.sim.image_scene import (
    IMAGE_SCENES,
    ImageScene,
    ImageSceneConfig,
    PinholeCamera,
    project_boxes,
    visible_fractions,
)


def paired_iou(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """IoU of row i of a with row i of b."""
    lo, hi = np.maximum(a[:, :2], b[:, :2]), np.minimum(a[:, 2:], b[:, 2:])
    inter = np.prod(np.clip(hi - lo, 0.0, None), axis=1)
    union = np.prod(a[:, 2:] - a[:, :2], axis=1) + np.prod(b[:, 2:] - b[:, :2], axis=1) - inter
    return inter / union


def level_camera() -> PinholeCamera:
    return PinholeCamera(ImageSceneConfig(pitch_rad=0.0, camera_height_m=1.0))


def test_a_point_on_the_optical_axis_projects_to_the_principal_point() -> None:
    config = ImageSceneConfig(pitch_rad=0.3, camera_height_m=2.0)
    camera = PinholeCamera(config)
    # 10 m along the pitched axis from the camera centre.
    point = camera.origin + 10.0 * np.array([0.0, np.cos(0.3), -np.sin(0.3)])
    uv, depth = camera.project(point[None, :])
    np.testing.assert_allclose(uv[0], [config.width_px / 2, config.height_px / 2], atol=1e-9)
    assert depth[0] == pytest.approx(10.0)
    # Right in the world is right in the image, up is up (v grows downwards).
    uv_right, _ = camera.project((point + [1.0, 0.0, 0.0])[None, :])
    uv_up, _ = camera.project((point + [0.0, 0.0, 1.0])[None, :])
    assert uv_right[0, 0] > uv[0, 0] and uv_up[0, 1] < uv[0, 1]


def test_box_height_follows_perspective() -> None:
    camera = level_camera()
    f = camera.focal
    heights = np.array([1.8, 1.8])
    feet = np.array([[0.0, 5.0], [0.0, 10.0]])
    boxes, depth = project_boxes(camera, feet, 0.5, heights)
    h_px = boxes[:, 3] - boxes[:, 1]
    # The box spans the person's near and far faces (depth +- 0.25 m): between f h / (y + 0.25)
    # and f h / (y - 0.25).
    assert np.all(h_px >= f * heights / (feet[:, 1] + 0.25) - 1e-9)
    assert np.all(h_px <= f * heights / (feet[:, 1] - 0.25) + 1e-9)
    np.testing.assert_allclose(depth, feet[:, 1])
    assert h_px[0] / h_px[1] == pytest.approx(2.0, rel=0.06)  # twice as far: half the size


def test_visible_fraction_counts_only_nearer_boxes() -> None:
    boxes = np.array([[0.0, 0.0, 10.0, 10.0], [5.0, 0.0, 15.0, 10.0], [100.0, 0, 110.0, 10.0]])
    depth = np.array([5.0, 10.0, 1.0])
    present = np.array([True, True, True])
    visible = visible_fractions(boxes, depth, present)
    # Box 1's left half lies behind box 0 (nearer); box 0 is in front; box 2 overlaps nothing.
    np.testing.assert_allclose(visible, [1.0, 0.5, 1.0])
    # A box that is not present hides nothing and is itself invisible.
    visible = visible_fractions(boxes, depth, np.array([False, True, True]))
    np.testing.assert_allclose(visible, [0.0, 1.0, 1.0])


def test_a_person_behind_a_nearer_one_is_hidden_and_never_detected() -> None:
    config = ImageSceneConfig(
        num_people=2, pitch_rad=0.0, camera_height_m=1.0, speed_mps=(0.0, 0.0), miss_prob=0.0
    )
    scene = ImageScene(config)
    scene.feet = np.array([[0.0, 4.0], [0.0, 12.0]])  # same bearing, the second far behind
    scene.heights = np.array([1.9, 1.7])
    for _ in range(20):
        f = scene.step()
        np.testing.assert_allclose(f.visible_fraction, [1.0, 0.0])
        assert 0 in f.detection_truth and 1 not in f.detection_truth


def test_truth_velocity_is_the_motion_of_the_box_centre() -> None:
    config = ImageSceneConfig(turn_std_radps=0.0, rate_hz=30.0, seed=4)
    scene = ImageScene(config)
    a = scene.step()
    b = scene.step()
    inside = a.in_image & b.in_image & (a.depth_m > 0)
    assert inside.sum() >= 3
    centre = lambda boxes: 0.5 * (boxes[:, :2] + boxes[:, 2:])  # noqa: E731
    moved = (centre(b.projected_boxes) - centre(a.projected_boxes)) * config.rate_hz
    # Finite difference over one frame vs the derivative at its start: a few px/s apart at most
    # (people nearer than 3 m are not in the scene, so the projection is smooth).
    speed = np.linalg.norm(a.truth_velocity[inside], axis=1)
    error = np.linalg.norm(moved[inside] - a.truth_velocity[inside], axis=1)
    assert np.all(error <= 0.05 * speed + 1.0)
    assert np.max(speed) > 10.0  # the check is not vacuous


@pytest.mark.parametrize("name", sorted(IMAGE_SCENES))
def test_detections_follow_the_detector_rules(name: str) -> None:
    config = IMAGE_SCENES[name](3)
    a, b = ImageScene(config), ImageScene(config)
    ious, false_positives, frames = [], 0, 150
    for _ in range(frames):
        fa, fb = a.step(), b.step()
        np.testing.assert_array_equal(fa.boxes, fb.boxes)  # seeded
        real = fa.detection_truth >= 0
        people = fa.detection_truth[real]
        # Only people in the image and visible enough are detected, each at most once.
        assert np.all(fa.in_image[people])
        assert np.all(fa.visible_fraction[people] >= config.min_visible)
        assert len(np.unique(people)) == len(people)
        assert np.all(fa.boxes[:, 2:] > fa.boxes[:, :2])
        assert np.all((fa.scores >= 0.0) & (fa.scores <= 1.0))
        ious.append(paired_iou(fa.boxes[real], fa.truth_boxes[people]))
        false_positives += int((~real).sum())
        # Truth boxes lie in the image.
        shown = fa.truth_boxes[fa.in_image]
        assert np.all(shown >= 0.0)
        assert np.all(shown[:, [0, 2]] <= config.width_px)
        assert np.all(shown[:, [1, 3]] <= config.height_px)
    # Box noise of 3 % of the height per edge: almost every true detection overlaps its person
    # by IoU >= 0.5; false positives arrive at the configured Poisson rate (+-5 sigma).
    assert np.mean(np.concatenate(ious) >= 0.5) > 0.95
    expected = config.false_positives_per_frame * frames
    assert abs(false_positives - expected) <= 5.0 * np.sqrt(expected)
