#!/usr/bin/env python3
"""rostest: the handoff nodelet's inputs and outputs, good and bad.

Good: a scan and a cloud in `laser` come back on ~scans_planning / ~clouds_planning in map with
their stamps and the points where map <- odom <- base_link <- laser puts them; a goal comes back
in base_link. Bad: zero stamps, inconsistent scans, broken cloud layouts, unknown frames, NaN
and zero-quaternion goals, goals stamped where tf has no data: each is dropped with a counted
reason and the nodelet keeps working. A second instance with absurd parameters reports them as
configuration errors and still publishes its seam health.
"""

from __future__ import annotations

import math
import threading
import unittest

import numpy as np
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped
from sensor_msgs import point_cloud2
from sensor_msgs.msg import LaserScan, PointCloud2, PointField
from std_msgs.msg import Header
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.msg import SeamHealth
from downstream_perception.planar import se2_matrix
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until
from downstream_perception.srv import TransformPose

MAP_ODOM = (2.0, 1.0, math.radians(10))
ODOM_BASE = (3.0, 0.0, math.radians(30))
BASE_LASER = (0.1, 0.0, 0.0)  # and 0.2 m up


MAP_LASER = se2_matrix(*MAP_ODOM) @ se2_matrix(*ODOM_BASE) @ se2_matrix(*BASE_LASER)


class HandoffInputsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_handoff_inputs")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "odom", now, *MAP_ODOM[:2], yaw=MAP_ODOM[2]),
                transform_stamped("odom", "base_link", now, *ODOM_BASE[:2], yaw=ODOM_BASE[2]),
                transform_stamped("base_link", "laser", now, *BASE_LASER[:2], z=0.2),
            ]
        )
        cls.lock = threading.Lock()
        cls.received: dict[str, list] = {"scans": [], "clouds": [], "goals": [], "absurd": []}
        cls.status: dict[str, DiagnosticStatus] = {}

        def keep(key: str):  # type: ignore[no-untyped-def]
            def on(msg) -> None:  # type: ignore[no-untyped-def]
                with cls.lock:
                    cls.received[key].append(msg)

            return on

        rospy.Subscriber("/handoff/scans_planning", PointCloud2, keep("scans"), queue_size=20)
        rospy.Subscriber("/handoff/clouds_planning", PointCloud2, keep("clouds"), queue_size=20)
        rospy.Subscriber("/handoff/goal_base", PoseStamped, keep("goals"), queue_size=20)
        rospy.Subscriber("/handoff_absurd/seam_health", SeamHealth, keep("absurd"), queue_size=5)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=20)
        cls.scan_pub = rospy.Publisher("/hi/scan", LaserScan, queue_size=20)
        cls.cloud_pub = rospy.Publisher("/hi/cloud", PointCloud2, queue_size=20)
        cls.goal_pub = rospy.Publisher("/goal", PoseStamped, queue_size=20)
        # Both nodelets share the manager process: one connection per topic.
        assert wait_until(lambda: cls.scan_pub.get_num_connections() >= 1, 20.0)
        assert wait_until(lambda: cls.cloud_pub.get_num_connections() >= 1, 20.0)
        assert wait_until(lambda: cls.goal_pub.get_num_connections() >= 1, 20.0)

    @classmethod
    def on_diagnostics(cls, msg: DiagnosticArray) -> None:
        with cls.lock:
            for s in msg.status:
                cls.status[s.name] = s

    def diagnostics(self, name: str) -> DiagnosticStatus:
        with self.lock:
            key = next((k for k in self.status if k.endswith(name)), None)
            self.assertIsNotNone(key, f"no status '{name}' in {list(self.status)}")
            return self.status[key]  # type: ignore[index]

    def value(self, name: str, key: str) -> str:
        values = {kv.key: kv.value for kv in self.diagnostics(name).values}
        self.assertIn(key, values)
        return values[key]

    def count(self, key: str) -> int:
        return int(self.value("handoff: seam", key))

    def wait_count(self, key: str, at_least: int) -> bool:
        return wait_until(lambda: self.count_or_zero(key) >= at_least, 10.0)

    def count_or_zero(self, key: str) -> int:
        with self.lock:
            for name, s in self.status.items():
                if name.endswith("handoff: seam"):
                    values = {kv.key: kv.value for kv in s.values}
                    return int(values.get(key, 0))
        return 0

    def latest(self, key: str):  # type: ignore[no-untyped-def]
        with self.lock:
            return self.received[key][-1] if self.received[key] else None

    def scan(self, stamp: rospy.Time | None = None, frame: str = "laser") -> LaserScan:
        # Four beams at 0, 90, 180, 270 degrees, 2 m each.
        return laser_scan(
            rospy.Time.now() if stamp is None else stamp,
            frame,
            [2.0, 2.0, 2.0, 2.0],
            0.0,
            math.pi / 2,
            0.05,
            10.0,
        )

    def cloud(self, frame: str = "laser") -> PointCloud2:
        header = Header(stamp=rospy.Time.now(), frame_id=frame)
        return point_cloud2.create_cloud_xyz32(header, [[1.0, 0.0, 0.0], [0.0, -2.0, 0.5]])

    def expected_map(self, points_laser: np.ndarray) -> np.ndarray:
        xy = (MAP_LASER @ np.c_[points_laser[:, :2], np.ones(len(points_laser))].T).T[:, :2]
        return np.c_[xy, points_laser[:, 2] + 0.2]

    # ------------------------------------------------------------------ good input
    def test_1_scans_and_clouds_come_back_in_map_at_their_stamps(self) -> None:
        scan = self.scan()
        self.scan_pub.publish(scan)
        self.assertTrue(wait_until(lambda: self.latest("scans") is not None, 10.0), "no scan")
        out = self.latest("scans")
        self.assertEqual(out.header.frame_id, "map")
        self.assertEqual(out.header.stamp, scan.header.stamp)
        got = np.array(list(point_cloud2.read_points(out, ("x", "y", "z"))))
        angles = np.arange(4) * math.pi / 2
        want = self.expected_map(np.c_[2 * np.cos(angles), 2 * np.sin(angles), np.zeros(4)])
        np.testing.assert_allclose(got, want, atol=1e-4)

        cloud = self.cloud()
        self.cloud_pub.publish(cloud)
        self.assertTrue(wait_until(lambda: self.latest("clouds") is not None, 10.0), "no cloud")
        out = self.latest("clouds")
        self.assertEqual((out.header.frame_id, out.header.stamp), ("map", cloud.header.stamp))
        got = np.array(list(point_cloud2.read_points(out, ("x", "y", "z"))))
        want = self.expected_map(np.array([[1.0, 0.0, 0.0], [0.0, -2.0, 0.5]]))
        np.testing.assert_allclose(got, want, atol=1e-4)

    # ------------------------------------------------------------------ bad input
    def test_2_malformed_scans_and_clouds_are_counted(self) -> None:
        topic = "/hi/scan"
        zero = self.scan(stamp=rospy.Time(0))
        self.scan_pub.publish(zero)
        short = self.scan()
        short.intensities = [1.0]  # one intensity for four ranges
        self.scan_pub.publish(short)
        flat = self.scan()
        flat.angle_increment = 0.0
        self.scan_pub.publish(flat)
        self.assertTrue(self.wait_count(f"{topic} rejected (malformed)", 3), "scans not rejected")
        # An unknown frame waits for tf that never comes, until the tf queue (3) drops it.
        for _ in range(6):
            self.scan_pub.publish(self.scan(frame="nowhere"))
            rospy.sleep(0.05)
        self.assertTrue(self.wait_count(f"{topic} tf failures", 3), "unknown frame not counted")

        broken = self.cloud()
        broken.data = broken.data[:-4]  # shorter than row_step * height
        self.cloud_pub.publish(broken)
        no_xyz = PointCloud2(header=Header(stamp=rospy.Time.now(), frame_id="laser"))
        no_xyz.fields = [PointField("intensity", 0, PointField.FLOAT32, 1)]
        no_xyz.height, no_xyz.width, no_xyz.point_step, no_xyz.row_step = 1, 1, 4, 4
        no_xyz.data = bytes(4)
        self.cloud_pub.publish(no_xyz)
        self.assertTrue(self.wait_count("/hi/cloud rejected (malformed)", 2), "clouds not rejected")

        # Still working: a good scan after all that comes back.
        with self.lock:
            self.received["scans"].clear()
        good = self.scan()
        self.scan_pub.publish(good)
        self.assertTrue(
            wait_until(
                lambda: (m := self.latest("scans")) is not None
                and m.header.stamp == good.header.stamp,
                10.0,
            ),
            "the nodelet stopped re-publishing scans after bad input",
        )

    def test_3_bad_goals_are_rejected_good_ones_handed_down(self) -> None:
        def goal(x: float, frame: str = "map", stamp: rospy.Time | None = None) -> PoseStamped:
            g = PoseStamped()
            g.header.frame_id = frame
            g.header.stamp = rospy.Time.now() if stamp is None else stamp
            g.pose.position.x, g.pose.position.y = x, 4.0
            g.pose.orientation.w = 1.0
            return g

        nan_goal = goal(float("nan"))
        self.goal_pub.publish(nan_goal)
        zero_q = goal(8.0)
        zero_q.pose.orientation.w = 0.0
        self.goal_pub.publish(zero_q)
        self.assertTrue(self.wait_count("goals rejected (bad pose)", 2), "bad goals not rejected")
        self.goal_pub.publish(goal(8.0, frame="nowhere"))
        # Stamped 30 s ago: the static transforms hold, so it is handed down; stamped in the
        # future beyond any tf: dropped (no transform at its stamp).
        self.goal_pub.publish(goal(8.0, stamp=rospy.Time.now() + rospy.Duration(30.0)))
        self.assertTrue(self.wait_count("goals dropped (no transform at stamp)", 1), "not dropped")

        rospy.wait_for_service("/handoff/transform_pose", 10.0)
        transform = rospy.ServiceProxy("/handoff/transform_pose", TransformPose)
        res = transform(nan_goal, "base_link")
        self.assertFalse(res.success)
        self.assertIn("not finite", res.message)

        good = goal(8.0, stamp=rospy.Time(0))
        self.goal_pub.publish(good)
        self.assertTrue(wait_until(lambda: self.latest("goals") is not None, 10.0), "no goal")
        out = self.latest("goals")
        self.assertEqual(out.header.frame_id, "base_link")
        # map <- base_link = (2, 1, 10 deg) . (3, 0, 30 deg): the lesson's (3.9266, -0.0586).
        self.assertAlmostEqual(out.pose.position.x, 3.9266, places=3)
        self.assertAlmostEqual(out.pose.position.y, -0.0586, places=3)

    def test_4_absurd_parameters_are_reported_and_survived(self) -> None:
        self.assertTrue(
            wait_until(lambda: len(self.received["absurd"]) >= 2, 10.0),
            "the absurd instance publishes no seam health",
        )
        health = self.latest("absurd")
        self.assertEqual(health.reference_range_m, 5.0)  # the NaN was refused
        self.assertTrue(wait_until(lambda: self.has_status("handoff_absurd: seam"), 10.0))
        status = self.diagnostics("handoff_absurd: seam")
        self.assertEqual(status.level, DiagnosticStatus.ERROR)
        errors = " | ".join(kv.value for kv in status.values if kv.key.startswith("config"))
        for name in ("health_rate_hz", "reference_range_m", "max_smear_m", "window_s"):
            self.assertIn(name, errors + status.message)
        # Values of the wrong type are named, not dropped without a word (roscpp's param()).
        self.assertIn("~max_correction_m is '0.5' (string), not a number", errors)
        self.assertIn("~track_topics has item 1 3 (int), not a string", errors)

    def has_status(self, name: str) -> bool:
        with self.lock:
            return any(k.endswith(name) for k in self.status)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "handoff_inputs", HandoffInputsTest)
