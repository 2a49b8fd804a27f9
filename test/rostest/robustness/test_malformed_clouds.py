#!/usr/bin/env python3
"""rostest: every malformed PointCloud2 layout reaches all four cloud consumers (obstacle layer,
3-D voxel layer, handoff relay, TSDF); each refuses every one with a counted reason, and a good
cloud sent after them is still used by all four (the manager process survived)."""

from __future__ import annotations

import threading
import unittest
from collections.abc import Callable

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2, PointField
from std_msgs.msg import Header
from tf2_ros import StaticTransformBroadcaster

from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import transform_stamped, wait_until

TOPIC = "/mc/points"
# A wall of points 1.5 m ahead of the lidar, 0.2 .. 1.0 m up (the lidar sits 0.3 m above map).
WALL = [[1.5, 0.05 * k - 0.5, 0.1 * h - 0.1] for k in range(21) for h in range(9)]


def good_cloud(stamp: rospy.Time) -> PointCloud2:
    return point_cloud2.create_cloud_xyz32(Header(stamp=stamp, frame_id="lidar"), WALL)


def malformed_clouds(stamp: rospy.Time) -> dict[str, PointCloud2]:
    """Each a small change of a good 4-point cloud that no consumer may read."""

    def variant(change: Callable[[PointCloud2], None]) -> PointCloud2:
        c = point_cloud2.create_cloud_xyz32(
            Header(stamp=stamp, frame_id="lidar"), [[1.0, 0.0, 0.5]] * 4
        )
        c.data = bytes(c.data)
        change(c)
        return c

    def fields(offsets: tuple[int, int, int], datatype: int = PointField.FLOAT32, count: int = 1):
        return [PointField(n, o, datatype, count) for n, o in zip("xyz", offsets, strict=True)]

    def setattrs(**values):  # type: ignore[no-untyped-def]
        return lambda c: [setattr(c, k, v) for k, v in values.items()]

    return {
        "point_step 0": variant(setattrs(point_step=0)),
        "z offset 4e9": variant(setattrs(fields=fields((0, 4, 4_000_000_000)))),
        "offsets past the point": variant(setattrs(fields=fields((4000, 4004, 4008)))),
        "offsets wrapping in 32 bits": variant(
            setattrs(fields=fields((0xFFFFFFF8, 0xFFFFFFFC, 0)))
        ),
        "width * point_step wrapping in 32 bits": variant(setattrs(width=0x10000000, row_step=12)),
        "data shorter than row_step * height": variant(lambda c: setattr(c, "data", c.data[:-1])),
        "data longer than row_step * height": variant(lambda c: setattr(c, "data", c.data + b"!")),
        "row_step < width * point_step": variant(setattrs(row_step=8)),
        "height huge": variant(setattrs(height=0xFFFFFFFF)),
        "no z field": variant(lambda c: setattr(c, "fields", c.fields[:2])),
        "float64 fields": variant(setattrs(fields=fields((0, 4, 8), PointField.FLOAT64))),
        "big-endian": variant(setattrs(is_bigendian=True)),
        "field count 0": variant(setattrs(fields=fields((0, 4, 8), count=0))),
    }


class MalformedCloudsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_malformed_clouds")
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [
                transform_stamped("map", "base_link", now),
                transform_stamped("base_link", "lidar", now, z=0.3),
            ]
        )
        cls.lock = threading.Lock()
        cls.status: dict[str, DiagnosticStatus] = {}
        cls.relayed: list[PointCloud2] = []

        def on_diagnostics(msg: DiagnosticArray) -> None:
            with cls.lock:
                for s in msg.status:
                    cls.status[s.name] = s

        def on_relayed(msg: PointCloud2) -> None:
            with cls.lock:
                cls.relayed.append(msg)

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=50)
        rospy.Subscriber("/handoff/clouds_planning", PointCloud2, on_relayed, queue_size=20)
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.pub = rospy.Publisher(TOPIC, PointCloud2, queue_size=50)
        # The consumers share the manager process: one connection.
        assert wait_until(lambda: cls.pub.get_num_connections() >= 1, 20.0)

    def values(self, status_suffix: str) -> dict[str, str]:
        with self.lock:
            key = next((k for k in self.status if k.endswith(status_suffix)), None)
            if key is None:
                return {}
            return {kv.key: kv.value for kv in self.status[key].values}

    def count(self, status_suffix: str, key_prefix: str) -> int:
        return sum(
            int(float(v)) for k, v in self.values(status_suffix).items() if k.startswith(key_prefix)
        )

    def test_every_consumer_refuses_every_layout_and_keeps_working(self) -> None:
        bad = malformed_clouds(rospy.Time.now())
        for msg in bad.values():
            self.pub.publish(msg)
            rospy.sleep(0.05)
        n = len(bad)
        counts = {
            "obstacle layer": lambda: self.count(
                "costmap: layer obstacles", "points: rejected (bad message: cloud layout)"
            ),
            "voxel layer": lambda: self.count("costmap: layer voxels", "source 'points' refused"),
            "handoff relay": lambda: self.count("handoff: seam", f"{TOPIC} rejected (malformed)"),
            "tsdf": lambda: self.count("tsdf: tsdf", "rejected (bad point cloud)"),
        }
        for consumer, count in counts.items():
            self.assertTrue(
                wait_until(lambda count=count: count() >= n, 15.0),
                f"{consumer} counted {count()} of {n} malformed clouds",
            )

        # All four still use a good cloud.
        good = good_cloud(rospy.Time.now())
        with self.lock:
            self.relayed.clear()
        for _ in range(3):
            good.header.stamp = rospy.Time.now()
            self.pub.publish(good)
            rospy.sleep(0.2)
        self.assertTrue(
            wait_until(
                lambda: self.costmap.received and self.costmap.cell(1.55, 0.05) == 100, 15.0
            ),
            "the wall 1.5 m ahead never became lethal",
        )
        self.assertTrue(
            wait_until(lambda: self.count("tsdf: tsdf", "frames integrated") >= 1, 15.0),
            f"the TSDF integrated nothing: {self.values('tsdf: tsdf')}",
        )
        self.assertTrue(
            wait_until(
                lambda: self.count("costmap: layer voxels", "source 'points' integrated") >= 1,
                15.0,
            ),
            f"the voxel layer integrated nothing: {self.values('costmap: layer voxels')}",
        )
        with self.lock:
            relayed = list(self.relayed)
        self.assertTrue(relayed, "the relay re-published nothing")
        self.assertEqual(relayed[-1].width * relayed[-1].height, len(WALL))


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "malformed_clouds", MalformedCloudsTest)
