#!/usr/bin/env python3
"""rostest: the VoxelObstacleLayer keeps a table top that rays pass under.

The depth simulator's floating table top (0.72-0.76 m) must be lethal in the costmap, while the
floor under it is seen (occupied floor voxels below the band, reached by rays passing under the
top) and nothing between the floor and the top is occupied. The open floor is not lethal.
"""

from __future__ import annotations

import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs import point_cloud2
from sensor_msgs.msg import CameraInfo, Image, PointCloud2
from std_msgs.msg import Bool
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until
from downstream_perception.sim.depth_camera import room_scene


class VoxelLayerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_voxel_layer")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        # late_camera: outside the simulated room, looking up (optical z = odom z).
        cls.static_tf.sendTransform(
            [
                transform_stamped("odom", "base_link", now, y=1.5),
                transform_stamped("odom", "late_camera", now, x=2.5, y=2.5, z=1.0),
            ]
        )
        cls.done = False
        cls.voxels: np.ndarray | None = None

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        def on_voxels(msg: PointCloud2) -> None:
            pts = list(point_cloud2.read_points(msg, field_names=("x", "y", "z")))
            cls.voxels = np.asarray(pts, dtype=float).reshape(-1, 3)

        cls.lock = threading.Lock()
        cls.warnings: list[str] = []
        cls.values: dict[str, str] = {}

        def on_diagnostics(msg: DiagnosticArray) -> None:
            with cls.lock:
                for status in msg.status:
                    cls.warnings += [kv.value for kv in status.values if "warning" in kv.key]
                    cls.values.update({kv.key: kv.value for kv in status.values})

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=20)
        rospy.Subscriber("/depth_sim/done", Bool, on_done, queue_size=1)
        rospy.Subscriber("/costmap/voxels/voxel_cloud", PointCloud2, on_voxels, queue_size=1)
        cls.costmap = CostmapClient("/costmap/costmap")

    def test_table_top_lethal_floor_under_it_seen(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        rospy.sleep(2.0)  # a costmap update and publish after the last frame
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        self.assertTrue(wait_until(lambda: self.voxels is not None, 10.0), "no voxel cloud")
        scene = room_scene()
        table = scene.boxes[1]
        tx, ty, tz = table.center
        hx, hy, _ = table.half_extents
        # The table top's columns are lethal, centre and near a corner.
        self.assertEqual(self.costmap.cell(tx, ty), 100)
        self.assertEqual(self.costmap.cell(tx + hx - 0.1, ty - hy + 0.1), 100)
        # Under the top (its footprint shrunk by 0.1 m): floor voxels are occupied (the floor was
        # seen through the space under the top), nothing between 0.1 m and the top is.
        v = self.voxels
        assert v is not None
        under = (np.abs(v[:, 0] - tx) < hx - 0.1) & (np.abs(v[:, 1] - ty) < hy - 0.1)
        self.assertGreater(int((under & (v[:, 2] < 0.05)).sum()), 10, "floor under it not seen")
        self.assertEqual(int((under & (v[:, 2] > 0.1) & (v[:, 2] < tz - 0.1)).sum()), 0)
        self.assertGreater(int((under & (np.abs(v[:, 2] - tz) < 0.05)).sum()), 20)
        # The open floor between the objects: not lethal.
        self.assertNotEqual(self.costmap.cell(0.0, 1.3), 100)
        self.assertNotEqual(self.costmap.cell(-1.0, -1.5), 100)

    def value(self, key: str) -> str | None:
        with self.lock:
            return self.values.get(key)

    def test_an_image_before_its_first_camera_info_waits_for_it(self) -> None:
        # voxel_layer.test's second depth source: its first image comes before its CameraInfo
        # (the two topics are not ordered against each other); it waits and is integrated then.
        if not rospy.has_param("/costmap/voxels/late"):
            self.skipTest("this launch has no 'late' source")
        image_pub = rospy.Publisher("/late_camera/depth", Image, queue_size=1)
        info_pub = rospy.Publisher("/late_camera/camera_info", CameraInfo, queue_size=1)
        self.assertTrue(wait_until(lambda: image_pub.get_num_connections() > 0, 20.0))
        self.assertTrue(wait_until(lambda: info_pub.get_num_connections() > 0, 20.0))
        waiting = "source 'late' depth images waiting for their first CameraInfo"
        integrated = "source 'late' integrated"
        self.assertTrue(wait_until(lambda: self.value(waiting) == "0", 20.0), self.value(waiting))
        side = 8
        image = Image()
        image.header.stamp = rospy.Time.now()
        image.header.frame_id = "late_camera"
        image.height = image.width = side
        image.encoding = "32FC1"
        image.is_bigendian = 0
        image.step = 4 * side
        image.data = np.full((side, side), 0.5, dtype="<f4").tobytes()  # 0.5 m: z = 1.5 m
        image_pub.publish(image)
        self.assertTrue(wait_until(lambda: self.value(waiting) == "1", 20.0), self.value(waiting))
        self.assertEqual(self.value(integrated), "0")
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        self.assertNotEqual(self.costmap.cell(2.5, 2.5), 100)
        info = CameraInfo()
        info.header = image.header
        info.width = info.height = side
        info.K = [8.0, 0.0, 3.5, 0.0, 8.0, 3.5, 0.0, 0.0, 1.0]
        info_pub.publish(info)
        self.assertTrue(
            wait_until(lambda: self.value(integrated) == "1", 20.0), self.value(integrated)
        )
        self.assertEqual(self.value(waiting), "0")
        # The image was integrated at its own stamp: the column above the camera is lethal.
        self.assertTrue(wait_until(lambda: self.costmap.cell(2.5, 2.5) == 100, 10.0))

    def test_stvl_keys_outside_an_stvl_configuration_are_unknown(self) -> None:
        # The layer's type is ours, not STVL's: STVL's keys are not adopted, so they are warned
        # as unknown keys (compatibility rule: no key is ignored silently).
        if not rospy.has_param("/costmap/voxels/voxel_decay"):
            self.skipTest("this launch's configuration has no STVL key")

        def warned(key: str) -> bool:
            with self.lock:
                return any(f"{key} is not a key" in w for w in self.warnings)

        self.assertTrue(wait_until(lambda: warned("/costmap/voxels/voxel_decay"), 20.0))
        self.assertTrue(
            wait_until(lambda: warned("/costmap/voxels/depth/max_z"), 5.0), str(self.warnings[-8:])
        )

    def test_removed_box_is_cleared(self) -> None:
        # voxel_layer_frustum.test: the simulator took the box away after half of the frames.
        if not rospy.get_param("~box_removed", False):
            self.skipTest("the box stays in this launch")
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        rospy.sleep(2.0)
        self.assertTrue(wait_until(lambda: self.costmap.received, 10.0), "no costmap")
        box = room_scene().boxes[0]
        bx, by, _ = box.center
        hx, hy, _ = box.half_extents
        xs = np.arange(bx - hx + 0.025, bx + hx, 0.05)
        ys = np.arange(by - hy + 0.025, by + hy, 0.05)
        cells = [self.costmap.cell(x, y) for x in xs for y in ys]
        lethal = sum(c == 100 for c in cells)
        # A voxel seen in every one of the first 10 frames reaches the clamp (3.5) and needs 8
        # misses to drop below the occupied threshold (0.5): the 20 frames after the removal give
        # them. Measured (the binding, the same frames): 0 of its 120 footprint cells left lethal
        # with frustum clearing and with ray clearing; with only 10 frames after the removal
        # 44 and 31 (hysteresis, not the clearing).
        self.assertLessEqual(lethal, 0.1 * len(cells), f"{lethal} of {len(cells)} still lethal")
        self.assertNotEqual(self.costmap.cell(bx, by), 100)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_voxel_layer", VoxelLayerTest)
