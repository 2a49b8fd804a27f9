#!/usr/bin/env python3
"""rostest: a source configured with costmap_2d's keys. obstacle_range (1 m, set at the costmap
level) limits marking, raytrace_range (2 m, set at the source) limits clearing, and the relative
topic `scan` is /scan (the node's namespace), as in costmap_2d."""

from __future__ import annotations

import math
import time
import unittest

import rospy
import rostest
from sensor_msgs.msg import LaserScan
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

LETHAL, FREE, UNKNOWN = 100, 0, -1


class Costmap2dKeysTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_2d_keys")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("base_link", "laser", now, x=0.05, y=0.05),
            ]
        )
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.pub = rospy.Publisher("/scan", LaserScan, queue_size=10)  # `topic: scan`
        assert wait_until(lambda: cls.pub.get_num_connections() >= 1, 20.0), "nobody on /scan"

    def test_obstacle_and_raytrace_range_and_topic(self) -> None:
        # Eight beams 45 degrees apart from the laser at (0.05, 0.05): +x at 1.5 m (beyond
        # obstacle_range: clears, never marks), +y at 0.8 m (marks), -x at 3 m (clears to 2 m).
        ranges = [math.inf] * 8
        ranges[0], ranges[2], ranges[4] = 1.5, 0.8, 3.0

        def drawn() -> bool:
            return self.costmap.received and self.costmap.cell(0.05, 0.85) == LETHAL

        def publish() -> None:
            self.pub.publish(
                laser_scan(rospy.Time.now(), "laser", ranges, 0.0, math.pi / 4, 0.05, 10.0)
            )
            time.sleep(0.2)

        deadline = time.time() + 20.0
        while not drawn() and time.time() < deadline:
            publish()
        self.assertTrue(drawn(), "the obstacle at 0.8 m (within obstacle_range) never marked")
        for _ in range(10):  # enough misses for a cell to read free (log-odds -0.405 each)
            publish()
        time.sleep(0.5)
        cell = self.costmap.cell
        self.assertNotEqual(cell(1.55, 0.05), LETHAL, "marked beyond obstacle_range 1 m")
        self.assertEqual(cell(1.25, 0.05), FREE, "cleared along the beam")
        self.assertEqual(cell(-1.75, 0.05), FREE, "cleared within raytrace_range 2 m")
        self.assertEqual(cell(-2.35, 0.05), UNKNOWN, "cleared beyond raytrace_range 2 m")


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "costmap_2d_keys", Costmap2dKeysTest)
