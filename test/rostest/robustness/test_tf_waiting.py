#!/usr/bin/env python3
"""rostest: messages a tf2 MessageFilter holds back are visible in diagnostics within seconds,
per consumer and frame, with the reason: an unknown frame, frames whose transforms tf2 refuses
(NaN, a zero quaternion), and a stamp 100 s in the future."""

from __future__ import annotations

import math
import threading
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sensor_msgs import point_cloud2
from sensor_msgs.msg import PointCloud2
from std_msgs.msg import Header
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

from downstream_perception.msg import DetectedObject, DetectedObjectArray
from downstream_perception.ros.util import transform_stamped, wait_until

# frame -> what a consumer must say about it
EXPECTED = {
    "ghost": "unknown to tf",
    "nan_frame": "unknown to tf",
    "zero_quaternion": "unknown to tf",
    "odom_lidar": "ahead of the clock",
}
CONSUMERS = {  # diagnostics status suffix -> key prefix of its waiting report
    "costmap: layer obstacles": "points: ",
    "handoff: seam": "/tw/points ",
    "tsdf: tsdf": "point clouds: ",
    "tracker: tracker": "",
}


class TfWaitingTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_tf_waiting")
        cls.lock = threading.Lock()
        cls.status: dict[str, DiagnosticStatus] = {}

        def on_diagnostics(msg: DiagnosticArray) -> None:
            with cls.lock:
                for s in msg.status:
                    cls.status[s.name] = s

        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=50)
        cls.static_tf = StaticTransformBroadcaster()
        now = rospy.Time.now()
        cls.static_tf.sendTransform(
            [transform_stamped("map", "base_link", now), transform_stamped("map", "lidar", now)]
        )
        cls.tf = TransformBroadcaster()
        cls.cloud_pub = rospy.Publisher("/tw/points", PointCloud2, queue_size=20)
        cls.detection_pub = rospy.Publisher("/tw/detections", DetectedObjectArray, queue_size=20)
        assert wait_until(lambda: cls.cloud_pub.get_num_connections() >= 1, 20.0)
        assert wait_until(lambda: cls.detection_pub.get_num_connections() >= 1, 20.0)

    def report(self, suffix: str, prefix: str) -> tuple[int, dict[str, str]]:
        with self.lock:
            for name, s in self.status.items():
                if name.endswith(suffix):
                    values = {kv.key: kv.value for kv in s.values}
                    return s.level, {
                        k[len(prefix) :]: v for k, v in values.items() if k.startswith(prefix)
                    }
        return -1, {}

    def test_every_consumer_says_what_waits_for_tf_and_why(self) -> None:
        now = rospy.Time.now()
        nan = transform_stamped("map", "nan_frame", now)
        nan.transform.translation.x = math.nan
        zero = transform_stamped("map", "zero_quaternion", now)
        zero.transform.rotation.w = 0.0
        # A moving frame (a static one holds at every stamp, the future's too).
        self.tf.sendTransform([nan, zero, transform_stamped("map", "odom_lidar", now)])
        for frame in EXPECTED:
            stamp = now + rospy.Duration(100.0) if frame == "odom_lidar" else now
            header = Header(stamp=stamp, frame_id=frame)
            self.cloud_pub.publish(point_cloud2.create_cloud_xyz32(header, [[1.0, 0.0, 0.5]]))
            d = DetectedObject(header=header, kind=DetectedObject.POSITION, score=0.9)
            d.position.x = 1.0
            self.detection_pub.publish(DetectedObjectArray(header=header, detections=[d]))

        def reported(suffix: str, prefix: str) -> bool:
            level, values = self.report(suffix, prefix)
            return level == DiagnosticStatus.WARN and all(
                reason in values.get(f"waiting for tf from '{frame}'", "")
                for frame, reason in EXPECTED.items()
            )

        for suffix, prefix in CONSUMERS.items():
            self.assertTrue(
                wait_until(lambda s=suffix, p=prefix: reported(s, p), 10.0),
                f"{suffix}: {self.report(suffix, prefix)}",
            )
            _, values = self.report(suffix, prefix)
            self.assertEqual(values.get("waiting for tf (> 0.5 s)"), "4", values)


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "tf_waiting", TfWaitingTest)
