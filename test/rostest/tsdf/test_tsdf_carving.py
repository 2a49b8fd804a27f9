#!/usr/bin/env python3
"""rostest: free-space carving erases an object that moved away.

The depth simulator takes the room's box away after 10 of 30 frames. The TSDF nodelet with
carve_free_space updates whole rays, so the box's faces turn back into free space when later
frames look through where it stood; the nodelet without carving updates only the band around
each depth and keeps them. Both meshes must still hold the rest of the room.
"""

from __future__ import annotations

import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from std_msgs.msg import Bool

from downstream_perception.ros.mesh_collector import MeshCollector
from downstream_perception.ros.util import wait_until
from downstream_perception.sim.depth_camera import box_signed_distance, room_scene


class TsdfCarvingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tsdf_carving")
        cls.done = False
        cls.status: dict[str, dict[str, str]] = {}

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                for name in ("tsdf_carving", "tsdf_plain"):
                    if s.name.endswith(f"{name}: tsdf"):
                        cls.status[name] = {kv.key: kv.value for kv in s.values}

        cls.carving = MeshCollector("/tsdf_carving/mesh")
        cls.plain = MeshCollector("/tsdf_plain/mesh")
        rospy.Subscriber("/depth_sim/done", Bool, on_done, queue_size=1)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)

    def test_carving_erases_the_box_that_moved_away(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 60.0), "the simulator did not finish")
        self.assertTrue(
            wait_until(
                lambda: all(
                    int(self.status.get(n, {}).get("frames integrated", 0)) == 30
                    for n in ("tsdf_carving", "tsdf_plain")
                ),
                10.0,
            ),
            f"diagnostics: {self.status}",
        )
        time.sleep(1.5)  # the next mesh update (2 Hz) after the last frame
        box = room_scene().boxes[0]
        counts = {}
        for name, listener in (("carving", self.carving), ("plain", self.plain)):
            corners = listener.corners()
            self.assertGreater(len(corners), 10000, name)  # the rest of the room
            on_box = np.abs(box_signed_distance(corners, box))
            counts[name] = int(np.sum((on_box < 0.02) & (corners[:, 2] > 0.1)))  # above the floor
        self.assertGreater(counts["plain"], 200, counts)  # the box stays without carving
        self.assertLess(counts["carving"], 10, counts)  # and is gone with it
        self.assertEqual(self.status["tsdf_carving"]["free-space carving"], "on")
        self.assertEqual(self.status["tsdf_plain"]["free-space carving"], "off")
        blocks = {n: int(self.status[n]["blocks"]) for n in ("tsdf_carving", "tsdf_plain")}
        self.assertGreater(blocks["tsdf_carving"], blocks["tsdf_plain"], blocks)

    def test_a_frame_without_any_return_does_not_carve_the_walls(self) -> None:
        # Frame 20 is +Inf everywhere: no valid depth in it says the sensor saw free space, so its
        # no-return pixels are ignored (counted) instead of carving through the room to
        # max_depth_m. Carving it wrecked the map (8.6 % ghosts after 19 more good frames).
        self.assertTrue(wait_until(lambda: self.done, 60.0), "the simulator did not finish")
        key = "no-return pixels not carved: too few valid depths in their frame (total)"
        self.assertTrue(
            wait_until(lambda: int(self.status.get("tsdf_carving", {}).get(key, 0)) > 0, 10.0),
            f"diagnostics: {self.status.get('tsdf_carving')}",
        )
        self.assertGreaterEqual(int(self.status["tsdf_carving"][key]), 320 * 240)
        time.sleep(1.5)  # the next mesh update
        corners = self.carving.corners()
        error = np.abs(room_scene().signed_distance(corners))
        self.assertLess(float(np.mean(error > 0.05)), 0.01)  # ghosts: more than a voxel off

    def test_slice_distance_cap_off_and_absurd(self) -> None:
        # tsdf_carving: ~slice_distance_max_m 0 turns the clearance topic off (not advertised);
        # tsdf_plain: -1 is refused at start-up, counted as a config error, 2 m used instead.
        self.assertTrue(
            wait_until(lambda: {"tsdf_carving", "tsdf_plain"} <= set(self.status), 20.0),
            f"diagnostics: {self.status}",
        )
        self.assertEqual(self.status["tsdf_carving"]["slice distance cap (m)"], "off")
        self.assertEqual(self.status["tsdf_plain"]["slice distance cap (m)"], "2")
        self.assertGreaterEqual(int(self.status["tsdf_plain"]["config errors"]), 1)
        self.assertEqual(int(self.status["tsdf_carving"]["config errors"]), 0)
        topics = {name for name, _ in rospy.get_published_topics()}
        self.assertIn("/tsdf_plain/slice_distance", topics)
        self.assertNotIn("/tsdf_carving/slice_distance", topics)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tsdf_carving", TsdfCarvingTest)
