#!/usr/bin/env python3
"""rostest: the TSDF slice reaches the costmap through the TsdfLayer.

A table top floating at 0.72-0.76 m (which a 2-D lidar at 0.2 m would never see) and a sphere at
0.9-1.5 m lie in the TSDF's 0.05-1.8 m band: their cells must be lethal in the costmap the
CostmapNodelet publishes, the open floor and the space under nothing must not be.
"""

from __future__ import annotations

import unittest

import numpy as np
import rospy
import rostest
from nav_msgs.msg import OccupancyGrid
from std_msgs.msg import Bool
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until
from downstream_perception.sim.depth_camera import room_scene


class TsdfCostmapTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tsdf_costmap")
        # The costmap needs a robot pose: parked at (0, 1.5) in odom.
        cls.static_tf = StaticTransformBroadcaster()
        cls.static_tf.sendTransform(transform_stamped("odom", "base_link", rospy.Time.now(), y=1.5))
        cls.done = False
        cls.slice: OccupancyGrid | None = None

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        def on_slice(msg: OccupancyGrid) -> None:
            cls.slice = msg

        rospy.Subscriber("/depth_sim/done", Bool, on_done, queue_size=1)
        rospy.Subscriber("/tsdf/slice", OccupancyGrid, on_slice, queue_size=1)
        cls.costmap = CostmapClient("/costmap/costmap")

    def test_table_top_and_sphere_are_lethal(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        rospy.sleep(2.0)  # a slice after the last frame, then a costmap update and publish
        self.assertIsNotNone(self.slice)
        self.assertEqual(self.slice.header.frame_id, "odom")
        slice_cells = np.asarray(self.slice.data)
        self.assertGreater(int((slice_cells == 100).sum()), 200)
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        scene = room_scene()
        table, sphere = scene.boxes[1], scene.spheres[0]
        self.assertEqual(self.costmap.cell(table.center[0], table.center[1]), 100)
        self.assertEqual(self.costmap.cell(table.center[0] + 0.3, table.center[1] - 0.2), 100)
        self.assertEqual(self.costmap.cell(sphere.center[0], sphere.center[1]), 100)
        # The open floor between the objects and outside the room: not lethal.
        self.assertNotEqual(self.costmap.cell(0.0, 1.3), 100)
        self.assertNotEqual(self.costmap.cell(-1.0, -1.5), 100)
        self.assertNotEqual(self.costmap.cell(2.7, 2.7), 100)
        # Lethal cells in the costmap are exactly the slice's occupied cells (same 5 cm grid).
        grid = self.costmap.grid()
        self.assertEqual(int((grid == 100).sum()), int((slice_cells == 100).sum()))


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tsdf_costmap", TsdfCostmapTest)
