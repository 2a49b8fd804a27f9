#!/usr/bin/env python3
"""rostest: the TSDF nodelet's ESDF on 12 simulated depth frames of the analytic room.

The room's floor lies 2.9 mm above the voxel layer z = 0, so that layer (and those below it)
is occupied and a free voxel k layers up is k layers from the nearest occupied one: its ESDF
value is (k - 1/2) * 5 cm, and between voxel centres away from other objects the interpolated
field is d = z - 0.025 m with gradient (0, 0, 1). ~esdf_slice holds the voxel layer at 1 m,
with the same values the service gives at those voxel centres.
"""

from __future__ import annotations

import time
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Point
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2
from std_msgs.msg import Bool

from downstream_perception.ros.util import wait_until
from downstream_perception.srv import EsdfDistance

MAX_DISTANCE = 0.8


class TsdfEsdfTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tsdf_esdf")
        cls.done = False
        cls.slice: PointCloud2 | None = None

        def on_done(msg: Bool) -> None:
            cls.done = cls.done or msg.data

        def on_slice(msg: PointCloud2) -> None:
            cls.slice = msg

        cls.band: PointCloud2 | None = None
        cls.status: dict[str, str] = {}

        def on_band(msg: PointCloud2) -> None:
            cls.band = msg

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                if s.name.endswith("tsdf: tsdf"):
                    cls.status = {kv.key: kv.value for kv in s.values}

        rospy.Subscriber("/tsdf/slice_distance", PointCloud2, on_band, queue_size=1)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        rospy.Subscriber("/depth_sim/done", Bool, on_done, queue_size=1)
        rospy.Subscriber("/tsdf/esdf_slice", PointCloud2, on_slice, queue_size=1)
        rospy.wait_for_service("/tsdf/esdf_distance", 20.0)
        cls.query = rospy.ServiceProxy("/tsdf/esdf_distance", EsdfDistance)

    def distances(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        reply = self.query([Point(*p) for p in points])
        gradients = np.array([[g.x, g.y, g.z] for g in reply.gradients]).reshape(-1, 3)
        return np.array(reply.distances), gradients, np.array(reply.observed, dtype=bool)

    def test_1_floor_distance_and_gradient(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        points = np.array([[0.0, 0.3, 0.1], [0.013, 0.27, 0.131], [-0.11, 0.2, 0.0625]])
        d, grad, observed = self.distances(points)
        self.assertTrue(observed.all())
        np.testing.assert_allclose(d, points[:, 2] - 0.025, atol=1e-6)
        np.testing.assert_allclose(grad, np.tile([0.0, 0.0, 1.0], (3, 1)), atol=1e-5)
        d, grad, observed = self.distances(np.array([[50.0, 0.0, 1.0]]))
        self.assertFalse(observed[0])
        self.assertTrue(np.isnan(d[0]) and np.isnan(grad).all())

    def test_2_slice_agrees_with_the_service(self) -> None:
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        time.sleep(1.5)  # a mesh tick (2 Hz) after the last frame
        self.assertTrue(wait_until(lambda: self.slice is not None, 10.0), "no ~esdf_slice")
        cloud = np.array(
            list(point_cloud2.read_points(self.slice, ("x", "y", "z", "distance"))), dtype=float
        )
        self.assertGreater(len(cloud), 2000)
        np.testing.assert_allclose(cloud[:, 2], 1.0, atol=1e-6)
        self.assertTrue((np.abs(cloud[:, 3]) <= MAX_DISTANCE + 1e-6).all())
        self.assertTrue((cloud[:, 3] < 0).any())  # behind the walls
        self.assertTrue((cloud[:, 3] > 0.3).any())  # open space
        sample = cloud[:: max(1, len(cloud) // 300)]
        d, _, observed = self.distances(sample[:, :3])
        self.assertGreater(int(observed.sum()), len(sample) // 2)
        np.testing.assert_allclose(d[observed], sample[observed, 3], atol=1e-6)

    def test_3_a_slice_clearance_cap_below_a_voxel_is_raised_to_one(self) -> None:
        # ~slice_distance_max_m 0.01 with 5 cm voxels: a config error, and the band's ESDF
        # capped at one voxel, so a free column reads (sqrt(k) - 1/2) * 5 cm for k = 1 (beside
        # an obstacle) or 2 (diagonal to one), the cap for any farther, occupied ones the same
        # towards free columns, negative.
        self.assertTrue(wait_until(lambda: self.done, 40.0), "the simulator did not finish")
        self.assertTrue(wait_until(lambda: self.band is not None, 10.0), "no ~slice_distance")
        self.assertTrue(wait_until(lambda: "config errors" in self.status, 10.0), self.status)
        self.assertEqual(self.status["slice distance cap (m)"], "0.05", self.status)
        self.assertGreaterEqual(int(self.status["config errors"]), 1)
        d = np.array([p[0] for p in point_cloud2.read_points(self.band, ("distance",))])
        self.assertGreater(len(d), 1000)
        values = set(np.round(d, 6).tolist())
        diagonal = round((np.sqrt(2.0) - 0.5) * 0.05, 6)
        self.assertLessEqual(values, {-0.05, -diagonal, -0.025, 0.025, diagonal, 0.05})
        self.assertLessEqual({-0.025, 0.025, 0.05}, values)

    def test_4_absurd_slice_windows_are_refused_and_the_defaults_kept(self) -> None:
        # ~slice_window_m -3 and ~slice_max_cells 1e12: two config errors naming them; the
        # whole map and the 4,000,000-cell cap apply.
        self.assertTrue(wait_until(lambda: "config errors" in self.status, 10.0), self.status)
        errors = [v for k, v in self.status.items() if k.startswith("config error ")]
        self.assertTrue(any("~slice_window_m = -3" in e for e in errors), errors)
        self.assertTrue(any("~slice_max_cells = 1e+12" in e for e in errors), errors)
        self.assertEqual(self.status["slice window (m)"], "whole map")
        self.assertEqual(self.status["slice max cells"], "4000000")
        self.assertEqual(self.status["slices cut to slice_max_cells (total)"], "0")

    def test_5_a_value_of_the_wrong_type_is_named_and_its_default_kept(self) -> None:
        # ~health_period_s "often" (a string): roscpp's param() would drop it without a word.
        self.assertTrue(wait_until(lambda: "config errors" in self.status, 10.0), self.status)
        errors = [v for k, v in self.status.items() if k.startswith("config error ")]
        expected = "~health_period_s is 'often' (string), not a number; using the default 10"
        self.assertTrue(any(expected in e for e in errors), errors)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "test_tsdf_esdf", TsdfEsdfTest)
