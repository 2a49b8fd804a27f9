#!/usr/bin/env python3
"""rostest: a spatio-temporal voxel layer configuration (stvl_config.yaml: STVL's plugin type and
README keys) runs as our VoxelObstacleLayer. STVL's keys are adopted (voxel_size -> z_resolution,
a 2 m column, voxel_decay -> decay_time_s, max_z -> the clearing source's raytrace_range), the
differences are named in diagnostics, a wall in the camera's cloud is lethal (its marking source's
band starts at 0.3 m) and, once gone, is cleared by the clearing source along the points' rays.

The camera sits 0.5 m above the odom origin looking along +x; the wall is at x = 1.525 m.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2
from std_msgs.msg import Header
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until

LETHAL = 100
NS = "/costmap/rgbd_obstacle_layer"


def wall(x: float, top: float) -> list[list[float]]:
    """Points (camera frame = x forward, z up, 0.5 m above odom) on a wall at x, y in [-0.5,
    0.5] m, z from 0.4 m to `top` above the floor."""
    ys = np.arange(-0.5, 0.501, 0.025)
    zs = np.arange(0.4, top + 1e-6, 0.05) - 0.5
    return [[x, float(y), float(z)] for y in ys for z in zs]


class StvlConfigTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_stvl_config")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("odom", "base_link", now),
                transform_stamped("odom", "camera", now, z=0.5),
            ]
        )
        cls.pub = rospy.Publisher("/camera1/depth/points", PointCloud2, queue_size=5)
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.lock = threading.Lock()
        cls.warnings: list[str] = []
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=20)

    @classmethod
    def on_diagnostics(cls, msg: DiagnosticArray) -> None:
        with cls.lock:
            for status in msg.status:
                if status.name.endswith(": costmap"):
                    cls.warnings = [kv.value for kv in status.values if "warning" in kv.key]

    def publish(self, points: list[list[float]], seconds: float) -> None:
        rate = rospy.Rate(5.0)
        end = rospy.Time.now() + rospy.Duration(seconds)
        while rospy.Time.now() < end and not rospy.is_shutdown():
            self.pub.publish(
                point_cloud2.create_cloud_xyz32(
                    Header(stamp=rospy.Time.now(), frame_id="camera"), points
                )
            )
            rate.sleep()
        rospy.sleep(1.0)  # a costmap update and publish after the last cloud

    def test_stvl_keys_adopted_and_wall_marked_then_cleared(self) -> None:
        # STVL's keys under ours (what the layer and its dynamic_reconfigure server read).
        self.assertEqual(rospy.get_param(f"{NS}/z_resolution"), 0.05)
        self.assertEqual(rospy.get_param(f"{NS}/z_voxels"), 40)  # 0 .. 2 m
        self.assertEqual(rospy.get_param(f"{NS}/decay_time_s"), 20.0)
        self.assertEqual(rospy.get_param(f"{NS}/rgbd1_clear/raytrace_range"), 7.0)
        self.assertTrue(wait_until(lambda: self.pub.get_num_connections() > 0, 20.0))
        self.publish(wall(1.525, 1.2), 2.0)
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        self.assertEqual(self.costmap.cell(1.525, 0.025), LETHAL)
        # Crossed by the clearing rays: seen free in 3-D (with the 40-voxel band, a column seen in
        # only a few voxels stays unknown under unknown_threshold 15, costmap_2d's column rule).
        self.assertNotEqual(self.costmap.cell(0.825, 0.025), LETHAL)
        # The wall moves back to 2.525 m and up to 1.95 m: the clearing source's rays to it pass
        # through every voxel of the old wall (0.4 .. 1.2 m at 1.525 m).
        self.publish(wall(2.525, 1.95), 3.0)
        self.assertEqual(self.costmap.cell(2.525, 0.025), LETHAL)
        self.assertNotEqual(self.costmap.cell(1.525, 0.025), LETHAL)
        with self.lock:
            warnings = " | ".join(self.warnings)
        for difference in ("STVL decay_model 0", "clearing frustum", "filter 'voxel'"):
            self.assertIn(difference, warnings)
        self.assertNotIn("not a key", warnings)  # every STVL key of the README is read


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_stvl_config", StvlConfigTest)
