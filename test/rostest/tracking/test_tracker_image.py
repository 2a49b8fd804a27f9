#!/usr/bin/env python3
"""rostest: the tracker nodelet in image mode on scripted pixel boxes.

Box 0 (60 x 120 px) moves right at 50 px/s, box 1 (50 x 110 px) stands still, both with 1 px
noise at 10 Hz in frame `camera`. Box 0 is hidden for frames 30-32. Tracks must stay in the
camera frame with box sizes and pixel velocities, one id per box across the gap; a metric
(POSITION) detection sent to an image-mode tracker is counted invalid, not guessed at; the
parameters the YAML leaves unset take the image-mode defaults.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray

import downstream_perception as dp
from downstream_perception.msg import DetectedObject, DetectedObjectArray, TrackedObjectArray
from downstream_perception.ros.util import wait_until

BOX0 = np.array([100.0, 100.0, 160.0, 220.0])  # x_min, y_min, x_max, y_max at t = 0
BOX0_VELOCITY = 50.0  # px/s along x
BOX1 = np.array([400.0, 120.0, 450.0, 230.0])
HIDDEN = range(30, 33)  # frames without box 0


class Boxes:
    def __init__(self) -> None:
        self.pub = rospy.Publisher("/detections", DetectedObjectArray, queue_size=10)
        self.rng = np.random.default_rng(2)
        self.frame = 0
        self.add_position_detection = False
        threading.Thread(target=self._run, daemon=True).start()

    def detection(self, header, box: np.ndarray, truth: int) -> DetectedObject:  # type: ignore[no-untyped-def]
        noisy = box + self.rng.normal(0.0, 1.0, size=4)
        return DetectedObject(
            header=header,
            kind=DetectedObject.BOX,
            class_id=2,
            label="pallet",
            score=0.9,
            x_min=noisy[0],
            y_min=noisy[1],
            x_max=noisy[2],
            y_max=noisy[3],
            truth_id=truth,
        )

    def _run(self) -> None:
        rate = rospy.Rate(10)
        while not rospy.is_shutdown():
            msg = DetectedObjectArray()
            msg.header.stamp = rospy.Time.now()
            msg.header.frame_id = "camera"
            shift = BOX0_VELOCITY * 0.1 * self.frame
            if self.frame not in HIDDEN:
                msg.detections.append(self.detection(msg.header, BOX0 + [shift, 0, shift, 0], 0))
            msg.detections.append(self.detection(msg.header, BOX1, 1))
            if self.add_position_detection:
                bad = DetectedObject(header=msg.header, kind=DetectedObject.POSITION, score=0.9)
                bad.position.x = 1.0
                msg.detections.append(bad)
                self.add_position_detection = False
            self.pub.publish(msg)
            self.frame += 1
            rate.sleep()


class TrackerImageTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tracker_image")
        cls.history: list[TrackedObjectArray] = []
        cls.status: dict[str, str] = {}
        rospy.Subscriber("/tracker/tracks", TrackedObjectArray, cls.history.append, queue_size=50)

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                if s.name.endswith("tracker: tracker"):
                    cls.status = {kv.key: kv.value for kv in s.values}

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        cls.boxes = Boxes()

    def test_1_boxes_tracked_in_pixels_through_a_gap(self) -> None:
        self.assertTrue(wait_until(lambda: self.boxes.frame > 45, 20.0), "boxes published")
        self.assertTrue(wait_until(lambda: len(self.history) > 40, 5.0), "tracks published")
        latest = self.history[-1]
        self.assertEqual(latest.header.frame_id, "camera")  # image tracks are not transformed
        by_truth = {t.truth_id: t for t in latest.tracks if t.state == t.CONFIRMED}
        self.assertEqual(set(by_truth), {0, 1})
        moving, still = by_truth[0], by_truth[1]
        self.assertAlmostEqual(moving.size_x, 60.0, delta=4.0)
        self.assertAlmostEqual(moving.size_y, 120.0, delta=4.0)
        self.assertAlmostEqual(moving.velocity.x, BOX0_VELOCITY, delta=15.0)
        self.assertLess(abs(moving.velocity.y), 15.0)
        self.assertLess(np.hypot(still.velocity.x, still.velocity.y), 15.0)
        self.assertAlmostEqual(still.position.x, 425.0, delta=3.0)  # box centre, px
        self.assertEqual(moving.label, "pallet")
        # The gap: box 0's track coasted (no detection) and kept its id.
        coasted = any(
            t.truth_id == 0 and t.state == t.COASTING for msg in self.history for t in msg.tracks
        )
        self.assertTrue(coasted, "box 0's track should coast while hidden")
        ids: dict[int, set[int]] = {}
        for msg in self.history:
            for t in msg.tracks:
                if t.state != t.TENTATIVE:
                    ids.setdefault(t.truth_id, set()).add(t.id)
        self.assertEqual({k: len(v) for k, v in ids.items()}, {0: 1, 1: 1}, ids)

    def test_2_metric_detection_in_image_mode_is_invalid(self) -> None:
        before = int(self.status.get("detections invalid (total)", 0))
        self.boxes.add_position_detection = True
        self.assertTrue(
            wait_until(
                lambda: int(self.status.get("detections invalid (total)", 0)) > before, 10.0
            ),
            f"diagnostics: {self.status}",
        )

    def test_3_unset_parameters_take_the_image_defaults(self) -> None:
        # Issue 21 defect 6: tracker_image.yaml sets only the mode (and min_iou); every key it
        # leaves unset whose image default differs from the metric one is written to the
        # parameter server with the image value; a key it sets keeps its value.
        image = dp.TrackerConfig.Mode.IMAGE
        differing = dict(dp.TrackerConfig.mode_specific_defaults(image))
        self.assertIn("min_hits", differing)
        for name, value in differing.items():
            self.assertAlmostEqual(rospy.get_param(f"/tracker/{name}"), value, msg=name)
        self.assertEqual(rospy.get_param("/tracker/min_iou"), 0.25)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tracker_image", TrackerImageTest)
