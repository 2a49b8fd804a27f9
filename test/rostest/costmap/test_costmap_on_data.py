#!/usr/bin/env python3
"""rostest: update_on_data. The costmap's timer ticks once per 50 s, so each costmap message
received in this test's first 45 s comes from a data-driven update. A scan with a post shows
the post; repeating the same scan (no cell changes) publishes nothing more; scans without the
post clear it; a track array shows its object. Test methods run in name order."""

from __future__ import annotations

import math
import time
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import LaserScan
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.msg import TrackedObject, TrackedObjectArray
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

POST_X = 2.025  # a cell centre (m, map = base_link = laser)
N_BEAMS = 720
LETHAL = 100
TRACK_X, TRACK_Y = -1.975, 1.525


def scan_ranges(with_post: bool) -> np.ndarray:
    """A 12 cm post at (POST_X, 0) or nothing (+Inf: no return, clears to raytrace range)."""
    angles = -math.pi + np.arange(N_BEAMS) * (2 * math.pi / N_BEAMS)
    ranges = np.full(N_BEAMS, np.inf, dtype=np.float32)
    if with_post:
        hit = (np.cos(angles) > 0.9) & (np.abs(POST_X * np.tan(angles)) < 0.06)
        ranges[hit] = POST_X / np.cos(angles[hit])
    return ranges


class CostmapOnDataTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_on_data")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("base_link", "laser", now),
            ]
        )
        cls.costmap = CostmapClient("/costmap_on_data/costmap")
        cls.scans = rospy.Publisher("/on_data/scan", LaserScan, queue_size=10)
        cls.tracks = rospy.Publisher("/on_data/tracks", TrackedObjectArray, queue_size=5)
        cls.started = time.time()
        assert wait_until(
            lambda: cls.scans.get_num_connections() > 0 and cls.tracks.get_num_connections() > 0,
            20.0,
        ), "the costmap never subscribed"

    def send_scans(self, with_post: bool, count: int) -> None:
        angle_increment = 2 * math.pi / N_BEAMS
        for _ in range(count):
            msg = laser_scan(
                rospy.Time.now(),
                "laser",
                scan_ranges(with_post),
                -math.pi,
                angle_increment,
                0.05,
                10.0,
            )
            self.scans.publish(msg)
            time.sleep(0.1)

    def value(self, x: float, y: float) -> int:
        return self.costmap.cell(x, y)

    def test_1_a_scan_shows_at_once(self) -> None:
        self.send_scans(True, 1)
        self.assertTrue(
            wait_until(lambda: self.costmap.received and self.value(POST_X, 0.0) == LETHAL, 10.0),
            "the post never reached the published costmap",
        )
        # Inflated around it in the same update (the inflation layer ran).
        self.assertGreater(self.value(POST_X - 0.15, 0.0), 0)
        self.assertLess(time.time() - self.started, 45.0)  # before any timer update

    def test_2_unchanged_data_publishes_nothing(self) -> None:
        time.sleep(0.5)  # let the first scan's messages arrive
        before = self.costmap.full_grids + self.costmap.updates
        self.send_scans(True, 10)  # the same post again: clamped evidence, no cell changes
        time.sleep(0.5)
        after = self.costmap.full_grids + self.costmap.updates
        # At most one more (a last cell settling); ten would mean "publish per scan".
        self.assertLessEqual(after - before, 1)
        self.assertEqual(self.value(POST_X, 0.0), LETHAL)

    def test_3_clearing_shows_at_once(self) -> None:
        self.send_scans(False, 30)
        self.assertTrue(
            wait_until(lambda: self.value(POST_X, 0.0) == 0, 10.0),
            f"the post was not cleared (cell {self.value(POST_X, 0.0)})",
        )

    def test_4_a_track_array_shows_at_once(self) -> None:
        msg = TrackedObjectArray()
        msg.header.stamp, msg.header.frame_id = rospy.Time.now(), "map"
        track = TrackedObject(id=7, state=TrackedObject.CONFIRMED, size_x=0.3, size_y=0.3)
        track.position.x, track.position.y = TRACK_X, TRACK_Y
        track.position_covariance = [1e-4, 0.0, 0.0, 1e-4]
        track.velocity_covariance = [1e-4, 0.0, 0.0, 1e-4]
        track.truth_id = -1
        msg.tracks.append(track)
        self.tracks.publish(msg)
        self.assertTrue(
            wait_until(lambda: self.value(TRACK_X, TRACK_Y) == LETHAL, 10.0),
            "the tracked object never reached the published costmap",
        )
        self.assertLess(time.time() - self.started, 45.0)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "costmap_on_data", CostmapOnDataTest)
