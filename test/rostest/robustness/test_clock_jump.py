#!/usr/bin/env python3
"""rostest: on simulated time, /clock jumps back 30 s. The costmap, the tracker and the TSDF must
notice (diagnostics count it), and keep publishing (integrating) at the new timeline's stamps
within seconds, instead of waiting until the clock passes its old maximum. The static transforms
are sent once, before the jump (nothing sends them again after it)."""

from __future__ import annotations

import math
import struct
import threading
import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from map_msgs.msg import OccupancyGridUpdate
from nav_msgs.msg import OccupancyGrid
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import CameraInfo, Image, LaserScan
from tf2_ros import StaticTransformBroadcaster, TransformBroadcaster

from downstream_perception.msg import DetectedObject, DetectedObjectArray, TrackedObjectArray
from downstream_perception.ros.costmap_client import CostmapClient
from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

START_S = 1000.0
JUMP_S = 30.0
PLANE_1M = struct.pack("<192f", *([1.0] * 192))  # the 16 x 12 depth image's data, 32FC1


class SimClock:
    """Publishes /clock at 100 Hz of wall time, advancing 10 ms a tick; jump() goes back."""

    def __init__(self) -> None:
        self.pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.lock = threading.Lock()
        self.now_s = START_S
        self.running = True
        threading.Thread(target=self.run, daemon=True).start()

    def run(self) -> None:
        while self.running:
            with self.lock:
                self.now_s += 0.01
                stamp = rospy.Time.from_sec(self.now_s)
            self.pub.publish(Clock(clock=stamp))
            time.sleep(0.01)

    def now(self) -> rospy.Time:
        with self.lock:
            return rospy.Time.from_sec(self.now_s)

    def jump(self, back_s: float) -> None:
        with self.lock:
            self.now_s -= back_s


class ClockJumpTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls) -> None:
        rospy.init_node("test_clock_jump")
        cls.clock = SimClock()
        cls.lock = threading.Lock()
        cls.stamps: dict[str, list[float]] = {"costmap": [], "tracks": [], "all_tracks": []}
        cls.status: dict[str, DiagnosticStatus] = {}

        def keep(key: str):  # type: ignore[no-untyped-def]
            def on(msg) -> None:  # type: ignore[no-untyped-def]
                with cls.lock:
                    cls.stamps[key].append(msg.header.stamp.to_sec())

            return on

        def on_tracks(msg: TrackedObjectArray) -> None:
            keep("all_tracks")(msg)
            if any(t.state == t.CONFIRMED for t in msg.tracks):
                keep("tracks")(msg)

        def on_diagnostics(msg: DiagnosticArray) -> None:
            with cls.lock:
                for s in msg.status:
                    cls.status[s.name] = s

        rospy.Subscriber("/costmap/costmap", OccupancyGrid, keep("costmap"), queue_size=10)
        rospy.Subscriber(
            "/costmap/costmap_updates", OccupancyGridUpdate, keep("costmap"), queue_size=50
        )
        rospy.Subscriber("/tracker/tracks", TrackedObjectArray, on_tracks, queue_size=50)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=50)
        cls.costmap = CostmapClient("/costmap/costmap")
        cls.scan_pub = rospy.Publisher("/cj/scan", LaserScan, queue_size=10)
        cls.detection_pub = rospy.Publisher("/cj/detections", DetectedObjectArray, queue_size=10)
        cls.depth_pub = rospy.Publisher("/cj/depth/image", Image, queue_size=10)
        cls.info_pub = rospy.Publisher("/cj/depth/camera_info", CameraInfo, queue_size=10)
        cls.static_tf = StaticTransformBroadcaster()
        cls.static_tf.sendTransform(
            [
                transform_stamped("base_link", "laser", cls.clock.now(), x=0.05, y=0.05),
                transform_stamped("base_link", "camera", cls.clock.now(), z=0.5),
            ]
        )
        cls.tf = TransformBroadcaster()
        cls.beam = 0  # the scan's one obstacle: beam 0 (+x) before the jump, beam 2 (+y) after
        threading.Thread(target=cls.sensors, daemon=True).start()

    @classmethod
    def sensors(cls) -> None:
        """Odometry at 20 Hz, a scan and a detection at 10 Hz, stamped with the sim clock."""
        tick = 0
        while not rospy.is_shutdown():
            stamp = cls.clock.now()
            cls.tf.sendTransform(transform_stamped("map", "base_link", stamp))
            if tick % 2 == 0:
                ranges = [math.inf] * 8
                ranges[cls.beam] = (
                    1.0  # hits the middle of a 0.1 m cell (the laser sits at 0.05, 0.05)
                )
                cls.scan_pub.publish(laser_scan(stamp, "laser", ranges, 0.0, math.pi / 4, 0.05, 10))
                d = DetectedObject(kind=DetectedObject.POSITION, score=0.9, class_id=1)
                d.header.stamp, d.header.frame_id = stamp, "laser"
                d.position.x, d.position.y = 1.5, -0.5
                d.position_covariance = [0.01, 0.0, 0.0, 0.01]
                msg = DetectedObjectArray(detections=[d])
                msg.header.stamp, msg.header.frame_id = stamp, "laser"
                cls.detection_pub.publish(msg)
                cls.publish_depth(stamp)
            tick += 1
            time.sleep(0.05)

    @classmethod
    def publish_depth(cls, stamp: rospy.Time) -> None:
        """A 16 x 12 depth image of a plane 1 m ahead (the camera looks up), and its CameraInfo."""
        width, height = 16, 12
        info = CameraInfo(width=width, height=height)
        info.header.stamp, info.header.frame_id = stamp, "camera"
        info.K = [10.0, 0.0, 7.5, 0.0, 10.0, 5.5, 0.0, 0.0, 1.0]
        cls.info_pub.publish(info)
        image = Image(height=height, width=width, encoding="32FC1", is_bigendian=0, step=4 * width)
        image.header = info.header
        image.data = PLANE_1M
        cls.depth_pub.publish(image)

    def newest(self, key: str) -> float:
        with self.lock:
            return self.stamps[key][-1] if self.stamps[key] else -1.0

    def key(self, suffix: str) -> str:
        with self.lock:
            return next((name for name in self.status if name.endswith(suffix)), "")

    def diagnostic(self, suffix: str, key: str) -> int:
        with self.lock:
            for name, s in self.status.items():
                if name.endswith(suffix):
                    for kv in s.values:
                        if kv.key == key:
                            return int(kv.value)
        return -1

    def test_costmap_tracker_and_tsdf_keep_working_after_the_clock_jumps_back(self) -> None:
        self.assertTrue(wait_until(lambda: self.newest("costmap") > START_S, 20.0), "no costmap")
        self.assertTrue(wait_until(lambda: self.newest("tracks") > START_S, 20.0), "no tracks")
        self.assertTrue(wait_until(lambda: self.costmap.cell(1.05, 0.05) == 100, 10.0))
        integrated = "frames integrated"
        self.assertTrue(wait_until(lambda: self.diagnostic("tsdf", integrated) > 0, 20.0))
        before = self.clock.now().to_sec()
        self.clock.jump(JUMP_S)
        time.sleep(0.5)
        integrated_at_jump = self.diagnostic("tsdf", integrated)
        type(self).beam = 2  # something new to draw after the jump
        after = lambda key: self.newest(key) < before - JUMP_S / 2  # noqa: E731
        self.assertTrue(
            wait_until(lambda: after("costmap") and self.costmap.cell(0.05, 1.05) == 100, 10.0),
            f"the costmap stalled after the jump (newest stamp {self.newest('costmap')}): "
            f"{self.status.get(self.key('costmap: layer obstacles'))}",
        )
        self.assertTrue(
            wait_until(lambda: after("tracks"), 10.0),
            f"tracks stalled after the jump: newest array {self.newest('all_tracks')}",
        )
        self.assertTrue(
            wait_until(lambda: self.diagnostic("costmap: costmap", "clock jumps back") >= 1, 10.0)
        )
        self.assertGreaterEqual(
            self.diagnostic("tracker: tracker", "clock jumps back (tracks reset)"), 1
        )
        # The TSDF integrates the new timeline's frames (their camera mount is a static
        # transform, sent before the jump only).
        self.assertTrue(
            wait_until(lambda: self.diagnostic("tsdf", integrated) >= integrated_at_jump + 5, 10.0),
            f"the TSDF stalled after the jump: {self.status.get(self.key('tsdf'))}",
        )
        jumps = "clock jumps back (waiting messages and tf reset)"
        self.assertTrue(wait_until(lambda: self.diagnostic("tsdf", jumps) >= 1, 10.0))


if __name__ == "__main__":
    rostest.rosrun("downstream_perception", "clock_jump", ClockJumpTest)
