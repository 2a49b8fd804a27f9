#!/usr/bin/env python3
"""rostest: a LaserScan source of the VoxelObstacleLayer marks, clears and leaves unseen space
unknown; a sensor_msgs/PointCloud source (costmap_2d's default data_type) marks within its own
height band only, and the robot's footprint is cleared (costmap_2d's footprint_clearing_enabled);
a source silent for longer than its expected_update_rate makes the layer not current; a live
dynamic_reconfigure change rebuilds the map, an invalid one is put back.

The scanner sits 0.3 m above the odom origin looking along +x with beams from -90 to +90 degrees.
A wall at x = 1.525 m answers the beams within 60 degrees of the axis; the others see nothing (+Inf,
inf_is_no_return: they clear to raytrace_range, 3 m).
"""

from __future__ import annotations

import math
import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import Point32
from sensor_msgs.msg import LaserScan, PointCloud
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

LETHAL, FREE, UNKNOWN = 100, 0, -1
ANGLES = np.radians(np.arange(-90.0, 90.5, 1.0))


def wall_ranges(wall: bool) -> np.ndarray:
    ranges = np.full(ANGLES.shape, math.inf)
    if wall:
        near = np.abs(ANGLES) < math.radians(60.0)
        ranges[near] = 1.525 / np.cos(ANGLES[near])  # mid-voxel: no rounding at a face
    return ranges


class VoxelLayerScanTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_voxel_layer_scan")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("odom", "base_link", now),
                transform_stamped("odom", "laser", now, z=0.3),
            ]
        )
        cls.pub = rospy.Publisher("/scan", LaserScan, queue_size=5)
        cls.bump = rospy.Publisher("/bump", PointCloud, queue_size=5)
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.lock = threading.Lock()
        cls.status: dict[str, DiagnosticStatus] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=20)

    @classmethod
    def on_diagnostics(cls, msg: DiagnosticArray) -> None:
        with cls.lock:
            for status in msg.status:
                cls.status[status.name] = status

    def message_of(self, suffix: str) -> tuple[int, str]:
        """(level, message) of the latest status whose name ends with `suffix`."""
        with self.lock:
            for name, status in self.status.items():
                if name.endswith(suffix):
                    return status.level, status.message
        return -1, ""

    def values_of(self, suffix: str) -> str:
        """The key/values of the latest status whose name ends with `suffix`, as one string."""
        with self.lock:
            for name, status in self.status.items():
                if name.endswith(suffix):
                    return " | ".join(f"{kv.key}: {kv.value}" for kv in status.values)
        return ""

    def publish(self, wall: bool, seconds: float) -> None:
        rate = rospy.Rate(5.0)
        end = rospy.Time.now() + rospy.Duration(seconds)
        while rospy.Time.now() < end and not rospy.is_shutdown():
            msg = laser_scan(
                rospy.Time.now(),
                "laser",
                wall_ranges(wall),
                float(ANGLES[0]),
                math.radians(1.0),
                0.05,
                10.0,
            )
            self.pub.publish(msg)
            rate.sleep()
        rospy.sleep(1.0)  # a costmap update and publish after the last scan

    def test_wall_marked_space_cleared_then_wall_removed(self) -> None:
        self.assertTrue(wait_until(lambda: self.pub.get_num_connections() > 0, 20.0))
        self.publish(wall=True, seconds=2.0)
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        self.assertEqual(self.costmap.cell(1.52, 0.0), LETHAL)
        self.assertEqual(self.costmap.cell(1.52, 0.5), LETHAL)
        self.assertEqual(self.costmap.cell(0.8, 0.0), FREE)  # between the scanner and the wall
        # On the +Inf beam at 75 degrees, 1.5 m out: (0.388, 1.449). (Not the 90-degree beam: its
        # float32 angle puts it a hair either side of the column face at x = 0.)
        self.assertEqual(self.costmap.cell(0.388, 1.449), FREE)
        self.assertEqual(self.costmap.cell(-1.0, 0.0), UNKNOWN)  # behind the scanner: unseen
        # The wall is gone: every beam sees nothing; 15 misses clear its voxels.
        self.publish(wall=False, seconds=3.0)
        self.assertEqual(self.costmap.cell(1.52, 0.0), FREE)
        self.assertEqual(self.costmap.cell(2.5, 0.0), FREE)  # beyond the wall, now seen

    def test_point_cloud_band_and_footprint(self) -> None:
        self.assertTrue(wait_until(lambda: self.bump.get_num_connections() > 0, 20.0))
        # Cell centres (5 cm cells from -3 m), so that no coordinate sits on a cell face.
        points = [
            (1.025, -1.025, 0.05),  # inside the source's band [0, 0.15] m: marks
            (1.025, -1.625, 0.5),  # above it (inside the layer's band): neither marks nor clears
            (0.225, 0.025, 0.05),  # under the robot (robot_radius 0.46 m): cleared each update
        ]
        rate = rospy.Rate(5.0)
        end = rospy.Time.now() + rospy.Duration(2.0)
        while rospy.Time.now() < end and not rospy.is_shutdown():
            msg = PointCloud()
            msg.header.stamp = rospy.Time.now()
            msg.header.frame_id = "base_link"
            msg.points = [Point32(x, y, z) for x, y, z in points]
            self.bump.publish(msg)
            rate.sleep()
        rospy.sleep(1.0)
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        self.assertEqual(self.costmap.cell(1.025, -1.025), LETHAL)
        self.assertNotEqual(self.costmap.cell(1.025, -1.625), LETHAL)
        self.assertEqual(self.costmap.cell(0.225, 0.025), FREE)

    def test_scan_with_zero_stamp_is_refused(self) -> None:
        self.assertTrue(wait_until(lambda: self.pub.get_num_connections() > 0, 20.0))
        msg = laser_scan(
            rospy.Time(0),
            "laser",
            wall_ranges(True),
            float(ANGLES[0]),
            math.radians(1.0),
            0.05,
            10.0,
        )
        for _ in range(3):
            self.pub.publish(msg)
            rospy.sleep(0.1)
        self.assertTrue(
            wait_until(
                lambda: "zero stamp" in self.message_of("layer voxels")[1]
                or "zero stamp" in self.values_of("layer voxels"),
                10.0,
            ),
            str(self.message_of("layer voxels")),
        )

    def test_silent_source_makes_the_layer_not_current(self) -> None:
        def named() -> bool:
            level, message = self.message_of("layer voxels")
            return level == DiagnosticStatus.WARN and "source 'silent' (/silent)" in message

        self.assertTrue(wait_until(named, 20.0), str(self.message_of("layer voxels")))
        self.assertIn("expected_update_rate 0.50 s", self.message_of("layer voxels")[1])
        # The costmap's own summary names it too (costmap_2d: "not current" stops move_base).
        self.assertTrue(
            wait_until(lambda: "source 'silent'" in self.message_of(": costmap")[1], 10.0),
            str(self.message_of(": costmap")),
        )

    def test_zz_reconfigure_rebuilds_or_refuses(self) -> None:  # last: it empties the map
        self.publish(wall=True, seconds=1.5)
        self.assertEqual(self.costmap.cell(1.52, 0.0), LETHAL)
        client = Client("/costmap/voxels", timeout=10.0)
        # An invalid value is refused and put back; the map is kept.
        config = client.update_configuration({"mark_threshold": -1})
        self.assertEqual(config["mark_threshold"], 0)
        self.assertTrue(
            wait_until(lambda: "voxel map invalid" in self.message_of("layer voxels")[1], 10.0),
            str(self.message_of("layer voxels")),
        )
        rospy.sleep(0.5)
        self.assertEqual(self.costmap.cell(1.52, 0.0), LETHAL)
        # A valid change of the column rebuilds the map empty (as costmap_2d resets its grid).
        config = client.update_configuration({"z_voxels": 12})
        self.assertEqual(config["z_voxels"], 12)
        self.assertTrue(
            wait_until(lambda: self.costmap.cell(1.52, 0.0) == UNKNOWN, 10.0),
            "the wall survived a change of z_voxels",
        )


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_voxel_layer_scan", VoxelLayerScanTest)
