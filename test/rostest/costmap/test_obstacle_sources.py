#!/usr/bin/env python3
"""rostest obstacle_sources: costmap_2d's observation-source keys keep their meaning and defaults
on the real costmap nodelet, and nothing is ignored silently (see obstacle_sources.yaml)."""

from __future__ import annotations

import math
import threading
import time
import unittest

import dynamic_reconfigure.client
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Point32
from sensor_msgs import point_cloud2
from sensor_msgs.msg import LaserScan, PointCloud, PointCloud2
from std_msgs.msg import Header
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

LETHAL, UNKNOWN = 100, -1
NAN = math.nan


class Diagnostics:
    """The latest status of each diagnostics name."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._status: dict[str, DiagnosticStatus] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diag, queue_size=20)

    def _on_diag(self, msg: DiagnosticArray) -> None:
        with self._lock:
            for status in msg.status:
                self._status[status.name] = status

    def layer(self, name: str) -> DiagnosticStatus | None:
        with self._lock:
            for key, status in self._status.items():
                if key.endswith(f"layer {name}"):
                    return status
        return None

    def costmap(self) -> DiagnosticStatus | None:
        with self._lock:
            for key, status in self._status.items():
                if key.endswith(": costmap"):
                    return status
        return None

    def values(self, name: str) -> dict[str, str]:
        status = self.layer(name)
        return {} if status is None else {kv.key: kv.value for kv in status.values}


class ObstacleSourcesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_obstacle_sources")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("base_link", "laser", now, x=0.05, y=0.05),
                transform_stamped("base_link", "laser_high", now, y=-1.0, z=2.5),
            ]
        )
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.diag = Diagnostics()
        cls.scan_pub = rospy.Publisher("/os/scan", LaserScan, queue_size=10)
        cls.high_pub = rospy.Publisher("/os/high_scan", LaserScan, queue_size=10)
        cls.cloud1_pub = rospy.Publisher("/os/cloud1", PointCloud, queue_size=10)
        cls.cloud2_pub = rospy.Publisher("/os/cloud2", PointCloud2, queue_size=10)
        # Each test asserts on its own topic (a subscriber of another type never connects).
        for pub in (cls.scan_pub, cls.high_pub, cls.cloud1_pub, cls.cloud2_pub):
            wait_until(lambda p=pub: p.get_num_connections() >= 1, 10.0)
        assert wait_until(lambda: cls.costmap.received, 20.0), "no costmap"

    @staticmethod
    def beams(first: float) -> list[float]:
        """Eight beams 45 degrees apart: +x at `first`, the others invalid (NaN)."""
        return [first] + [NAN] * 7

    def scan(self, pub: rospy.Publisher, frame: str, first: float, times: int) -> None:
        for _ in range(times):
            pub.publish(
                laser_scan(rospy.Time.now(), frame, self.beams(first), 0.0, math.pi / 4, 0.05, 10.0)
            )
            time.sleep(0.15)

    def test_1_laser_source_with_costmap2d_defaults_marks_but_does_not_clear(self) -> None:
        cell = self.costmap.cell
        self.scan(self.scan_pub, "laser", 1.0, 5)  # three hits make a cell lethal
        self.assertTrue(wait_until(lambda: cell(1.05, 0.05) == LETHAL), "the return never marked")
        # A farther return along the same beam: with clearing false (costmap_2d's default) the
        # first obstacle and the cells before it stay as they were.
        self.scan(self.scan_pub, "laser", 2.0, 12)
        self.assertTrue(wait_until(lambda: cell(2.05, 0.05) == LETHAL), "2 m never marked")
        time.sleep(0.5)
        self.assertEqual(cell(1.05, 0.05), LETHAL, "cleared although clearing defaults to false")
        self.assertEqual(cell(0.55, 0.05), UNKNOWN, "cleared although clearing defaults to false")

    def test_2_point_cloud_is_the_default_data_type(self) -> None:
        def publish() -> None:
            msg = PointCloud()
            msg.header.stamp = rospy.Time.now()
            msg.header.frame_id = "laser"
            msg.points = [Point32(-1.0, 0.0, 0.5)]
            self.cloud1_pub.publish(msg)
            time.sleep(0.15)

        self.assertGreaterEqual(
            self.cloud1_pub.get_num_connections(), 1, "no sensor_msgs/PointCloud subscriber"
        )
        for _ in range(5):
            publish()
        self.assertTrue(
            wait_until(lambda: self.costmap.cell(-0.95, 0.05) == LETHAL),
            "a sensor_msgs/PointCloud source (data_type defaults to PointCloud) never marked",
        )
        self.assertEqual(self.diag.values("obstacles").get("legacy: data type"), "PointCloud")

    def test_3_height_band_applies_to_laser_scans(self) -> None:
        # The scanner is 2.5 m up: above max_obstacle_height 2 m (the default), so its points
        # neither mark nor clear, as in costmap_2d (which filters the projected scan by z).
        self.scan(self.high_pub, "laser_high", 1.0, 6)

        def counted() -> bool:
            v = self.diag.values("obstacles")
            return int(v.get("high: messages integrated", "0")) >= 6 and (
                int(v.get("high: points outside height band (total)", "0")) >= 6
            )

        self.assertTrue(wait_until(counted), str(self.diag.values("obstacles")))
        time.sleep(0.3)
        self.assertNotEqual(self.costmap.cell(1.05, -0.95), LETHAL)

    def test_4_flat_voxel_layer_marks_within_its_column_only(self) -> None:
        header = Header(stamp=rospy.Time.now(), frame_id="laser")
        for _ in range(5):
            header.stamp = rospy.Time.now()
            # 0.5 m is inside the column [.., 1.0 m]; 1.5 m is above it (though below 2 m).
            self.cloud2_pub.publish(
                point_cloud2.create_cloud_xyz32(header, [(0.0, 1.0, 0.5), (1.0, 1.0, 1.5)])
            )
            time.sleep(0.15)
        self.assertTrue(
            wait_until(lambda: self.costmap.cell(0.05, 1.05) == LETHAL), "inside the column"
        )
        time.sleep(0.3)
        self.assertNotEqual(self.costmap.cell(1.05, 1.05), LETHAL, "marked above the column")
        warnings = " | ".join(
            v for k, v in self.diag.values("voxels").items() if k.startswith("parameter warning ")
        )
        self.assertIn("mark_threshold is not supported", warnings)

    def test_5_silent_source_and_topic_without_publisher_are_named(self) -> None:
        def named() -> bool:
            v = self.diag.values("obstacles")
            return "expected_update_rate" in v.get("silent: problem", "") and (
                "no publisher on /os/nopub" in v.get("nopub: problem", "")
            )

        self.assertTrue(wait_until(named, 20.0), str(self.diag.values("obstacles")))
        status = self.diag.layer("obstacles")
        assert status is not None
        self.assertEqual(status.level, DiagnosticStatus.WARN)
        self.assertIn("source 'silent' (/os/silent)", status.message)
        # The costmap's own summary names the source too, not just "a layer is not current".
        self.assertTrue(
            wait_until(
                lambda: "source 'silent' (/os/silent)"
                in getattr(self.diag.costmap(), "message", ""),
                10.0,
            ),
            str(getattr(self.diag.costmap(), "message", None)),
        )

    def test_6_wrong_typed_and_unknown_keys_are_warned(self) -> None:
        v = self.diag.values("obstacles")
        warnings = " | ".join(val for k, val in v.items() if k.startswith("parameter warning "))
        self.assertIn("/costmap/obstacles/transform_tolerance is '0.3' (string)", warnings)
        self.assertIn("/costmap/obstacles/bogus_layer_key is not a key", warnings)
        self.assertIn("/costmap/obstacles/plain/obstacle_rang is not a key", warnings)

    def test_7_rejected_reconfigure_values_are_reverted_and_errors_clear(self) -> None:
        client = dynamic_reconfigure.client.Client("/costmap/obstacles", timeout=10)
        self.assertEqual(client.update_configuration({"p_hit": 1.5})["p_hit"], 0.7)
        self.assertTrue(
            wait_until(lambda: self.diag.values("obstacles").get("config errors") == "1"),
            "the rejected p_hit is not in diagnostics",
        )
        # Another change: the rejected value is not sent again, its error stays.
        after = client.update_configuration({"footprint_clearing_enabled": False})
        self.assertEqual(after["p_hit"], 0.7)
        self.assertEqual(self.diag.values("obstacles").get("config errors"), "1")
        # A valid p_hit fixes it: the error leaves the diagnostics.
        self.assertEqual(client.update_configuration({"p_hit": 0.75})["p_hit"], 0.75)
        self.assertTrue(
            wait_until(lambda: self.diag.values("obstacles").get("config errors") == "0"),
            "the fixed error stayed",
        )
        client.update_configuration({"footprint_clearing_enabled": True})

        inflation = dynamic_reconfigure.client.Client("/costmap/inflation", timeout=10)
        self.assertEqual(
            inflation.update_configuration({"inflation_radius": -1.0})["inflation_radius"], 0.3
        )
        self.assertTrue(
            wait_until(lambda: self.diag.values("inflation").get("config errors") == "1")
        )
        self.assertEqual(
            inflation.update_configuration({"inflation_radius": 0.35})["inflation_radius"], 0.35
        )
        self.assertTrue(
            wait_until(lambda: self.diag.values("inflation").get("config errors") == "0")
        )


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "obstacle_sources", ObstacleSourcesTest)
