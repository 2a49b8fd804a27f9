#!/usr/bin/env python3
"""rostest: malformed scans, unknown frames, zero stamps, late tf and absurd parameters are
rejected with a counted reason, and the nodelet keeps working."""

from __future__ import annotations

import math
import time
import unittest

import rospy
import rostest
import tf2_ros
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import LaserScan

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until


class BadInputTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_costmap_bad_input")
        cls.clients = {
            "ok": CostmapClient("/costmap/costmap"),
            "absurd": CostmapClient("/costmap_absurd/costmap"),
        }
        cls.status: dict[str, tuple[int, str, dict[str, str]]] = {}

        def on_diag(msg: DiagnosticArray) -> None:
            for s in msg.status:
                cls.status[s.name] = (s.level, s.message, {kv.key: kv.value for kv in s.values})

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=20)
        cls.pub = rospy.Publisher("/test_scan", LaserScan, queue_size=50)
        cls.static_tf = tf2_ros.StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("map", "laser", now, x=0.05, y=0.05),
            ]
        )
        cls.tf = tf2_ros.TransformBroadcaster()
        deadline = time.time() + 20.0
        while cls.pub.get_num_connections() < 2 and time.time() < deadline:
            time.sleep(0.1)

    # ------------------------------------------------------------------ helpers
    def scan(
        self,
        ranges: list[float],
        frame: str = "laser",
        stamp: rospy.Time | None = None,
        angle_increment: float = 2 * math.pi / 8,
        angle_max: float | None = None,
    ) -> LaserScan:
        msg = LaserScan()
        msg.header.frame_id = frame
        msg.header.stamp = rospy.Time.now() if stamp is None else stamp
        msg.angle_min = 0.0
        msg.angle_increment = angle_increment
        msg.angle_max = angle_max if angle_max is not None else angle_increment * (len(ranges) - 1)
        msg.range_min = 0.05
        msg.range_max = 10.0
        msg.ranges = ranges
        return msg

    def publish(self, msg: LaserScan, times: int = 1) -> None:
        for _ in range(times):
            msg.header.stamp = (
                rospy.Time.now() if msg.header.stamp != rospy.Time(0) else msg.header.stamp
            )
            self.pub.publish(msg)
            time.sleep(0.05)

    def wait_for(self, predicate, timeout: float = 15.0) -> bool:  # type: ignore[no-untyped-def]
        return wait_until(predicate, timeout)

    def cell(self, key: str, x: float, y: float) -> int:
        return self.clients[key].cell(x, y)

    def layer(self, name: str = "costmap: layer obstacles") -> tuple[int, str, dict[str, str]]:
        key = next((k for k in self.status if k.endswith(name)), None)
        self.assertIsNotNone(key, f"no diagnostics status ending in '{name}': {list(self.status)}")
        return self.status[key]  # type: ignore[index]

    def rejected(self, reason_prefix: str) -> int:
        values = self.layer()[2]
        return sum(
            int(v) for k, v in values.items() if k.startswith(f"scan: rejected ({reason_prefix}")
        )

    # ------------------------------------------------------------------ tests
    def test_1_good_scan_marks_then_garbage_is_rejected_and_map_survives(self) -> None:
        # One beam along +x hits at 1.0 m -> the cell containing (1.05, 0.05) becomes lethal.
        good = [1.0] + [math.inf] * 7
        self.publish(self.scan(good), times=5)
        self.assertTrue(
            self.wait_for(
                lambda: self.clients["ok"].received and self.cell("ok", 1.05, 0.05) == 100
            )
        )

        # All-NaN and all -Inf scans: ignored beams, no marks, no crash.
        self.publish(self.scan([math.nan] * 8), times=3)
        self.publish(self.scan([-math.inf] * 8), times=3)
        # Malformed headers: zero increment, ranges that do not match the angles, zero stamp.
        self.publish(self.scan([1.0] * 8, angle_increment=0.0), times=2)
        self.publish(self.scan([1.0] * 8, angle_max=0.1), times=2)
        zero = self.scan([1.0] * 8, stamp=rospy.Time(0))
        self.pub.publish(zero)
        # Unknown frame: waits for tf that never comes, then is dropped by the tf queue.
        for _ in range(12):
            self.pub.publish(self.scan([1.0] * 8, frame="no_such_frame"))
            time.sleep(0.05)
        # Late tf: a frame whose only transform is 60 s newer than the scan (older than the cache).
        now = rospy.Time.now()
        self.tf.sendTransform(transform_stamped("map", "late_laser", now))
        time.sleep(0.3)
        self.tf.sendTransform(transform_stamped("map", "late_laser", rospy.Time.now()))
        self.pub.publish(self.scan([1.0] * 8, frame="late_laser", stamp=now - rospy.Duration(60.0)))

        self.assertTrue(self.wait_for(lambda: self.rejected("bad message") >= 4), self.layer())
        self.assertTrue(self.wait_for(lambda: self.rejected("tf") >= 2), self.layer())
        values = self.layer()[2]
        self.assertGreaterEqual(int(values["scan: rejected (bad message: zero stamp)"]), 1)
        self.assertGreaterEqual(int(values["scan: beams invalid (total)"]), 48)
        self.assertEqual(self.layer()[0], 1, "a layer that rejected scans reports WARN")

        # Still alive and still integrating: a new obstacle along +y appears.
        other = [math.inf, math.inf, 1.0] + [math.inf] * 5  # beam 2 points along +y
        self.publish(self.scan(other), times=5)
        self.assertTrue(self.wait_for(lambda: self.cell("ok", 0.05, 1.05) == 100))
        self.assertEqual(self.cell("ok", 1.05, 0.05), 100, "the first obstacle is still there")
        self.assertEqual(self.cell("ok", -1.5, -0.8), -1, "unseen cells stay unknown")

    def test_2_absurd_parameters_are_reported_and_defaults_used(self) -> None:
        self.assertTrue(
            self.wait_for(lambda: self.clients["absurd"].received), "absurd costmap never published"
        )
        info = self.clients["absurd"].message().info
        self.assertAlmostEqual(info.resolution, 0.05, places=6)  # default, not -0.1
        self.assertEqual((info.width, info.height), (200, 200))  # 10 m default at 0.05 m
        self.assertTrue(
            self.wait_for(lambda: any(k.endswith("costmap_absurd: costmap") for k in self.status))
        )
        key = next(k for k in self.status if k.endswith("costmap_absurd: costmap"))
        level, message, values = self.status[key]
        self.assertEqual(level, 2)
        self.assertIn("update_frequency", message)
        self.assertGreaterEqual(int(values["config errors"]), 4)
        layer_key = next(k for k in self.status if k.endswith("costmap_absurd: layer obstacles"))
        layer_level, _, layer_values = self.status[layer_key]
        self.assertEqual(layer_level, 2)
        errors = [v for k, v in layer_values.items() if k.startswith("config error ")]
        self.assertGreaterEqual(int(layer_values["config errors"]), 2)
        self.assertTrue(any("p_hit" in e for e in errors), errors)
        self.assertTrue(any("far" in e and "1e+15" in e for e in errors), errors)
        inflation_key = next(
            k for k in self.status if k.endswith("costmap_absurd: layer inflation")
        )
        inflation_level, _, inflation_values = self.status[inflation_key]
        self.assertEqual(inflation_level, 2, inflation_values)
        inflation_errors = [v for k, v in inflation_values.items() if k.startswith("config error ")]
        self.assertTrue(any("inflation_radius" in e for e in inflation_errors), inflation_errors)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "costmap_bad_input", BadInputTest)
