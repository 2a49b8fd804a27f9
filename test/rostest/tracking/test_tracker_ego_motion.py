#!/usr/bin/env python3
"""rostest: the tracker nodelet on detections seen from a robot driving at 1 m/s in odom.

Two parked objects and one walking object (0.8 m/s along y in odom) are detected in base_link at
10 Hz with 5 cm noise. Tracks must come out in odom, the parked ones with ~zero velocity (the
robot's own motion is not object motion), the walker with its velocity, each object under one
id. Then the walker disappears (its track must coast, die and get DELETE markers), and malformed
detection arrays (NaN, unknown frame, zero stamp) are counted without stopping the tracker.
"""

from __future__ import annotations

import math
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from tf2_ros import TransformBroadcaster
from visualization_msgs.msg import Marker, MarkerArray

from downstream_perception.msg import DetectedObject, DetectedObjectArray, TrackedObjectArray
from downstream_perception.ros.util import transform_stamped, wait_until

ROBOT_SPEED = 1.0  # m/s along odom x
PARKED = np.array([[4.0, 1.5], [7.0, -1.0]])
WALKER_START = np.array([6.0, -3.0])
WALKER_VELOCITY = np.array([0.0, 0.8])


class Scene:
    def __init__(self) -> None:
        self.t0 = rospy.Time.now()
        self.walker_visible = True
        self.inject_nan = False  # one NaN detection in the next frame (bad input)
        self.tf = TransformBroadcaster()
        self.pub = rospy.Publisher("/detections", DetectedObjectArray, queue_size=10)
        self.rng = np.random.default_rng(1)
        threading.Thread(target=self._run, daemon=True).start()

    def _run(self) -> None:
        rate = rospy.Rate(10)
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            t = (now - self.t0).to_sec()
            robot_x = ROBOT_SPEED * t
            self.tf.sendTransform(transform_stamped("odom", "base_link", now, x=robot_x))
            objects = [(k, PARKED[k]) for k in range(2)]
            if self.walker_visible:
                objects.append((2, WALKER_START + WALKER_VELOCITY * t))
            msg = DetectedObjectArray()
            msg.header.stamp = now
            msg.header.frame_id = "base_link"
            for truth, position in objects:
                d = DetectedObject()
                d.header = msg.header
                d.kind = DetectedObject.POSITION
                d.class_id = 1
                d.label = "person"
                d.score = 0.9
                d.position.x = position[0] - robot_x + self.rng.normal(0, 0.05)
                d.position.y = position[1] + self.rng.normal(0, 0.05)
                d.position_covariance = [0.0025, 0.0, 0.0, 0.0025]
                d.size_x = d.size_y = 0.5
                d.truth_id = truth
                msg.detections.append(d)
            if self.inject_nan:
                bad = DetectedObject(kind=DetectedObject.POSITION, score=0.9, truth_id=-1)
                bad.position.x = float("nan")
                msg.detections.append(bad)
                self.inject_nan = False
            self.pub.publish(msg)
            rate.sleep()


class TrackerEgoMotionTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tracker_ego_motion")
        cls.history: list[TrackedObjectArray] = []
        cls.deleted: set[int] = set()
        cls.status: dict[str, str] = {}
        rospy.Subscriber("/tracker/tracks", TrackedObjectArray, cls.history.append, queue_size=50)

        def on_markers(msg: MarkerArray) -> None:
            for m in msg.markers:
                if m.action == Marker.DELETE and m.ns == "track_box":
                    cls.deleted.add(m.id)

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                if s.name.endswith("tracker: tracker"):
                    cls.status = {kv.key: kv.value for kv in s.values}

        rospy.Subscriber("/tracker/markers", MarkerArray, on_markers, queue_size=50)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        cls.scene = Scene()

    def wait_for(self, predicate, timeout_s: float = 15.0) -> bool:  # type: ignore[no-untyped-def]
        return wait_until(predicate, timeout_s)

    def confirmed(self) -> list:
        if not self.history:
            return []
        return [t for t in self.history[-1].tracks if t.state == t.CONFIRMED]

    def test_1_tracks_in_odom_without_ego_motion(self) -> None:
        self.assertTrue(self.wait_for(lambda: len(self.confirmed()) == 3), "three confirmed tracks")
        time.sleep(2.0)  # let the velocities converge
        latest = self.history[-1]
        self.assertEqual(latest.header.frame_id, "odom")
        by_truth = {t.truth_id: t for t in latest.tracks if t.state == t.CONFIRMED}
        self.assertEqual(set(by_truth), {0, 1, 2})
        gate = 13.8  # chi-square, 2 dof, 99.9 %: the error must fit the track's own covariance
        for k in range(2):
            t = by_truth[k]
            error = np.array([t.velocity.x, t.velocity.y])
            d2 = error @ np.linalg.inv(np.reshape(t.velocity_covariance, (2, 2))) @ error
            # Leaked ego-motion would read -1 m/s here: far outside both bounds.
            self.assertLess(d2, gate, f"parked object {k}: velocity {error}")
            self.assertLess(float(np.linalg.norm(error)), 0.6, f"parked object {k}")
            self.assertLess(
                math.hypot(t.position.x - PARKED[k][0], t.position.y - PARKED[k][1]), 0.2
            )
            self.assertEqual(t.label, "person")
        walker = by_truth[2]
        error = np.array([walker.velocity.x, walker.velocity.y]) - WALKER_VELOCITY
        d2 = error @ np.linalg.inv(np.reshape(walker.velocity_covariance, (2, 2))) @ error
        self.assertLess(d2, gate, f"walker velocity error {error}")
        # One id per object over the whole run.
        ids: dict[int, set[int]] = {}
        for msg in self.history:
            for t in msg.tracks:
                if t.state != t.TENTATIVE:
                    ids.setdefault(t.truth_id, set()).add(t.id)
        self.assertTrue(all(len(v) == 1 for v in ids.values()), ids)

    def test_2_a_vanished_object_coasts_then_dies_with_delete_markers(self) -> None:
        walker_id = next(
            t.id for t in self.history[-1].tracks if t.truth_id == 2 and t.state == t.CONFIRMED
        )
        self.scene.walker_visible = False
        self.assertTrue(
            self.wait_for(
                lambda: any(
                    t.id == walker_id and t.state == t.COASTING for t in self.history[-1].tracks
                ),
                5.0,
            ),
            "the walker's track should coast",
        )
        self.assertTrue(
            self.wait_for(lambda: all(t.id != walker_id for t in self.history[-1].tracks), 5.0),
            "the walker's track should die after max_age_s",
        )
        self.assertTrue(self.wait_for(lambda: walker_id % 2147483647 in self.deleted, 3.0))

    def test_3_bad_detections_are_counted_and_survived(self) -> None:
        self.scene.inject_nan = True
        pub = rospy.Publisher("/detections", DetectedObjectArray, queue_size=50)
        time.sleep(0.5)
        # A frame nobody publishes: held by the tf MessageFilter until its queue (20) overflows.
        for _ in range(25):
            unknown = DetectedObjectArray()
            unknown.header.stamp = rospy.Time.now()
            unknown.header.frame_id = "no_such_frame"
            pub.publish(unknown)
            time.sleep(0.01)
        zero = DetectedObjectArray()
        zero.header.frame_id = "base_link"
        pub.publish(zero)
        self.assertTrue(
            self.wait_for(
                lambda: int(self.status.get("detections invalid (total)", 0)) >= 1
                and any(k.startswith("rejected (tf") for k in self.status)
                and int(self.status.get("rejected (bad message: zero stamp)", 0)) >= 1,
                15.0,
            ),
            f"diagnostics: {self.status}",
        )
        count = len(self.history)
        self.assertTrue(self.wait_for(lambda: len(self.history) > count + 5, 5.0), "still tracking")


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tracker_ego_motion", TrackerEgoMotionTest)
