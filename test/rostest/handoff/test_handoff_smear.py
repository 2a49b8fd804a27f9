#!/usr/bin/env python3
"""rostest: stamp-correct transforms keep a spinning robot's walls sharp; "latest" smears them.

The harness spins base_link in odom at 90 deg/s (tf at 200 Hz, true stamps) inside a square room
with walls at x, y = +-5 m, and publishes a 360-beam scan every 0.1 s, 30 ms after its stamp.
- The costmap nodelet transforms each scan at its stamp: every lethal cell lies within one cell
  of a wall.
- The harness places the same scans with the latest transform (a switch that exists only here):
  beams that hit a wall at 5 m land ~5 m x tan(90 deg/s x 30 ms) = 0.236 m away.
- The handoff nodelet measures the ~30 ms age and quotes the same smear; it hands the lesson's
  goal (8, 4) in map to (3.9266, -0.0586) in the lesson's base frame.
"""

from __future__ import annotations

import math
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import LaserScan
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

from downstream_perception.msg import SeamHealth
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until
from downstream_perception.srv import TransformPose

YAW_RATE = math.radians(90.0)
LATENCY = 0.030
HALF = 5.0  # walls at +-5 m
BEAMS = 360


def ranges_at(yaw: float) -> np.ndarray:
    """Ranges from the origin to the square room's walls, beam angles -pi.. in base_link."""
    phi = yaw + (-math.pi + np.arange(BEAMS) * 2 * math.pi / BEAMS)
    c, s = np.cos(phi), np.sin(phi)
    with np.errstate(divide="ignore"):
        tx = np.where(np.abs(c) > 1e-12, HALF / np.abs(c), np.inf)
        ty = np.where(np.abs(s) > 1e-12, HALF / np.abs(s), np.inf)
    return np.minimum(tx, ty)


class HandoffSmearTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_handoff_smear")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "odom", now),
                # The lesson's frames, for the goal handoff golden.
                transform_stamped("map", "lesson_odom", now, 2.0, 1.0, yaw=math.radians(10)),
                transform_stamped("lesson_odom", "lesson_base", now, 3.0, yaw=math.radians(30)),
            ]
        )
        cls.tf = TransformBroadcaster()
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.t0 = time.time()
        cls.running = True
        cls.scan_pub = rospy.Publisher("/scan", LaserScan, queue_size=10)
        cls.displacements: list[float] = []
        cls.health: SeamHealth | None = None
        cls.goal_base: PoseStamped | None = None
        rospy.Subscriber("/scan", LaserScan, cls.place_with_latest, queue_size=10)
        rospy.Subscriber("/handoff/seam_health", SeamHealth, cls.on_health, queue_size=1)
        rospy.Subscriber("/handoff/goal_base", PoseStamped, cls.on_goal_base, queue_size=1)
        cls.goal_pub = rospy.Publisher("/goal", PoseStamped, queue_size=1)
        cls.costmap = CostmapClient("/costmap/costmap")
        threading.Thread(target=cls.spin_tf, daemon=True).start()
        threading.Thread(target=cls.scan, daemon=True).start()

    @classmethod
    def yaw_at(cls, stamp: rospy.Time) -> float:
        return YAW_RATE * (stamp.to_sec() - cls.t0)

    @classmethod
    def spin_tf(cls) -> None:
        while cls.running and not rospy.is_shutdown():
            stamp = rospy.Time.now()
            cls.tf.sendTransform(
                transform_stamped("odom", "base_link", stamp, yaw=cls.yaw_at(stamp))
            )
            time.sleep(0.005)

    @classmethod
    def scan(cls) -> None:
        while cls.running and not rospy.is_shutdown():
            stamp = rospy.Time.now()
            ranges = ranges_at(cls.yaw_at(stamp))
            msg = laser_scan(stamp, "base_link", ranges, -math.pi, 2 * math.pi / BEAMS, 0.1, 10.0)
            time.sleep(LATENCY)  # the scan reaches the network 30 ms after its stamp
            cls.scan_pub.publish(msg)
            time.sleep(0.1 - LATENCY)

    @classmethod
    def place_with_latest(cls, msg: LaserScan) -> None:
        """The wrong way: the latest transform on arrival, not the one at the stamp."""
        try:
            latest = cls.buffer.lookup_transform("map", "base_link", rospy.Time(0))
        except tf2_ros.TransformException:
            return
        q = latest.transform.rotation
        yaw_latest = 2 * math.atan2(q.z, q.w)
        yaw_true = cls.yaw_at(msg.header.stamp)
        r = np.asarray(msg.ranges)
        a = msg.angle_min + np.arange(r.size) * msg.angle_increment
        at_5m = np.abs(r - HALF) < 0.05  # beams that hit a wall 5 m away, head on
        true_pts = np.stack([r * np.cos(a + yaw_true), r * np.sin(a + yaw_true)])
        wrong_pts = np.stack([r * np.cos(a + yaw_latest), r * np.sin(a + yaw_latest)])
        d = np.hypot(*(wrong_pts - true_pts))[at_5m]
        if d.size:
            cls.displacements.append(float(d.mean()))

    @classmethod
    def on_health(cls, msg: SeamHealth) -> None:
        cls.health = msg

    @classmethod
    def on_goal_base(cls, msg: PoseStamped) -> None:
        cls.goal_base = msg

    @classmethod
    def tearDownClass(cls) -> None:
        cls.running = False

    def test_1_stamp_correct_costmap_is_sharp_latest_smears(self) -> None:
        self.assertTrue(wait_until(lambda: self.costmap.received, 20.0), "no costmap")
        rospy.sleep(4.0)  # ~40 scans over more than a full turn
        grid = self.costmap.grid()
        ys, xs = np.nonzero(grid == 100)
        self.assertGreater(xs.size, 500, "walls not in the costmap")
        cx = -6.0 + (xs + 0.5) * 0.05
        cy = -6.0 + (ys + 0.5) * 0.05
        wall_distance = np.minimum(np.abs(np.abs(cx) - HALF), np.abs(np.abs(cy) - HALF))
        stamp_correct = float(wall_distance.max())
        self.assertLessEqual(stamp_correct, 0.05, "a lethal cell more than one cell off a wall")
        self.assertGreater(len(self.displacements), 20)
        latest = float(np.median(self.displacements))
        expected = HALF * math.tan(YAW_RATE * LATENCY)
        msg = (
            f"\nwall error with stamp-correct tf (costmap): {stamp_correct * 100:.1f} cm max; "
            f"with the latest tf: {latest * 100:.1f} cm at 5 m (lesson: {expected * 100:.1f} cm)"
        )
        print(msg)
        rospy.loginfo(msg)
        # The smear is the rotation during the transform's age (30 ms + tf publishing jitter).
        self.assertGreater(latest, 0.6 * expected)
        self.assertLess(latest, 1.6 * expected)

    def test_2_seam_health_quotes_age_and_smear(self) -> None:
        self.assertTrue(
            wait_until(lambda: self.health is not None and self.health.inputs[0].messages > 20, 20),
            "no seam health",
        )
        h = self.health
        self.assertAlmostEqual(h.yaw_rate_rps, YAW_RATE, delta=0.1)
        scan = h.inputs[0]
        self.assertEqual(scan.topic, "/scan")
        self.assertGreater(scan.transform_age_p50_s, LATENCY - 0.002)
        self.assertLess(scan.transform_age_p50_s, LATENCY + 0.04)
        self.assertGreater(scan.expected_smear_m, 0.2)
        self.assertTrue(any("expected smear" in w for w in h.warnings), h.warnings)
        self.assertEqual(h.map_odom_correction_m, 0.0)
        print(
            f"\nseam health: scan age p50 {scan.transform_age_p50_s * 1e3:.1f} ms, "
            f"p95 {scan.transform_age_p95_s * 1e3:.1f} ms, expected smear at 5 m "
            f"{scan.expected_smear_m * 100:.1f} cm, yaw rate {h.yaw_rate_rps:.3f} rad/s"
        )

    def test_3_goal_handed_down_at_its_stamp(self) -> None:
        rospy.wait_for_service("/handoff/transform_pose", 10.0)
        transform = rospy.ServiceProxy("/handoff/transform_pose", TransformPose)
        goal = PoseStamped()
        goal.header.frame_id = "map"  # stamp 0: the (static) latest
        goal.pose.position.x, goal.pose.position.y = 8.0, 4.0
        goal.pose.orientation.w = 1.0
        res = transform(goal, "lesson_base")
        self.assertTrue(res.success, res.message)
        self.assertAlmostEqual(res.pose.pose.position.x, 3.9266, delta=1e-4)
        self.assertAlmostEqual(res.pose.pose.position.y, -0.0586, delta=1e-4)
        bad = transform(goal, "no_such_frame")
        self.assertFalse(bad.success)
        self.assertIn("no_such_frame", bad.message)
        # On the topic, into the spinning base_link at the goal's own stamp.
        stamp = rospy.Time.now() - rospy.Duration(0.2)
        goal.header.stamp = stamp
        self.goal_pub.publish(goal)
        self.assertTrue(wait_until(lambda: self.goal_base is not None, 5.0), "no goal_base")
        out = self.goal_base
        self.assertEqual(out.header.frame_id, "base_link")
        self.assertEqual(out.header.stamp, stamp)
        yaw = self.yaw_at(stamp)
        c, s = math.cos(yaw), math.sin(yaw)
        self.assertAlmostEqual(out.pose.position.x, c * 8.0 + s * 4.0, delta=0.02)
        self.assertAlmostEqual(out.pose.position.y, -s * 8.0 + c * 4.0, delta=0.02)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "handoff_smear", HandoffSmearTest)
