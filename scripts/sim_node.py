#!/usr/bin/env python3
"""Simulator node: a robot drives a synthetic world with a 2-D lidar.

Publishes sensor_msgs/LaserScan on `scan` (frame `laser`, stamped with the measurement time),
tf map->odom (a drifting "localizer" correction) and odom->base_link at ~tf_rate_hz, a static
base_link->laser, and std_msgs/Bool(True) on latched `sim_done` when the trajectory has ended (tf
and scans go on from the final pose). With ~detection_rate_hz > 0 it also plays an object
detector: the world's moving objects within ~detection_range_m on `detections`
(DetectedObjectArray in base_link, Gaussian position noise, sizes, labels, truth ids).
Parameters: docs/demo.md ("Lidar simulator").
"""

from __future__ import annotations

import math

import numpy as np
import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Bool

from downstream_perception.msg import DetectedObjectArray
from downstream_perception.planar import se2_matrix
from downstream_perception.ros.util import detection_array, laser_scan, transform_stamped
from downstream_perception.sim import WORLDS, Lidar, LidarConfig, aisle_drive, stand


def to_transform(
    parent: str, child: str, m: np.ndarray, stamp: rospy.Time, z: float = 0.0
) -> TransformStamped:
    """parent <- child from a 3 x 3 SE(2) matrix."""
    yaw = math.atan2(m[1, 0], m[0, 0])
    return transform_stamped(parent, child, stamp, x=m[0, 2], y=m[1, 2], z=z, yaw=yaw)


class SimNode:
    def __init__(self) -> None:
        p = rospy.get_param
        world_name = str(p("~world", "warehouse_aisle"))
        if world_name not in WORLDS:
            rospy.logerr(
                "sim: unknown ~world '%s' (choose from %s); using warehouse_aisle",
                world_name,
                sorted(WORLDS),
            )
            world_name = "warehouse_aisle"
        self.world = WORLDS[world_name]()
        speed = float(p("~speed_mps", 1.0))
        if not math.isfinite(speed) or speed <= 0.0:
            rospy.logerr("sim: ~speed_mps must be positive, got %s; using 1.0", speed)
            speed = 1.0
        if str(p("~trajectory", "aisle_drive")) == "stand":
            duration = float(p("~duration_s", 20.0))
            if not math.isfinite(duration) or duration <= 0.0:
                rospy.logerr("sim: ~duration_s must be positive, got %s; using 20", duration)
                duration = 20.0
            self.trajectory = stand(float(p("~stand_x", 2.0)), float(p("~stand_y", 0.0)), duration)
        else:
            self.trajectory = aisle_drive(speed)
        self.scan_rate = max(0.1, float(p("~scan_rate_hz", 10.0)))
        self.detection_rate = max(0.0, float(p("~detection_rate_hz", 0.0)))
        self.detection_noise = max(0.0, float(p("~detection_noise_m", 0.03)))
        self.detection_range = float(p("~detection_range_m", 15.0))
        self.tf_rate = max(self.scan_rate, self.detection_rate, float(p("~tf_rate_hz", 50.0)))
        self.lidar = Lidar(
            LidarConfig(
                num_beams=int(p("~num_beams", 360)),
                range_max=float(p("~range_max_m", 30.0)),
                noise_std_m=float(p("~noise_std_m", 0.01)),
                dropout_prob=float(p("~dropout_prob", 0.0)),
                seed=int(p("~seed", 0)),
            )
        )
        self.laser_z = float(p("~laser_height_m", 0.2))
        self.laser_x = float(p("~laser_x_m", 0.0))
        self.start_delay = float(p("~start_delay_s", 1.0))
        self.loop = bool(p("~loop", False))
        self.frames = {  # each key spelt out: the docs test finds the parameters by name
            "map": str(p("~map_frame", "map")),
            "odom": str(p("~odom_frame", "odom")),
            "base": str(p("~base_frame", "base_link")),
            "laser": str(p("~laser_frame", "laser")),
        }
        ox, oy, oyaw = (float(v) for v in p("~odom_offset", [0.5, -0.2, 0.05]))
        self.map_odom = se2_matrix(ox, oy, oyaw)
        self.odom_map = np.linalg.inv(self.map_odom)

        self.scan_pub = rospy.Publisher("scan", LaserScan, queue_size=10)
        self.detection_pub = rospy.Publisher("detections", DetectedObjectArray, queue_size=10)
        self.rng = np.random.default_rng(int(p("~seed", 0)) + 1)
        self.class_ids: dict[str, int] = {}  # one class id per label, in order of appearance
        self.done_pub = rospy.Publisher("sim_done", Bool, queue_size=1, latch=True)
        self.tf = tf2_ros.TransformBroadcaster()
        self.static_tf = tf2_ros.StaticTransformBroadcaster()
        self.static_tf.sendTransform(
            to_transform(
                self.frames["base"],
                self.frames["laser"],
                se2_matrix(self.laser_x, 0.0, 0.0),
                rospy.Time.now(),
                self.laser_z,
            )
        )
        self.start = rospy.Time.now()
        self.done = False
        self.ticks = 0
        self.scan_every = max(1, round(self.tf_rate / self.scan_rate))
        self.detect_every = (
            max(1, round(self.tf_rate / self.detection_rate)) if self.detection_rate > 0 else 0
        )

    def sim_time(self, stamp: rospy.Time) -> float:
        t = max(0.0, (stamp - self.start).to_sec() - self.start_delay)
        if self.loop and self.trajectory.duration > 0:
            t = t % self.trajectory.duration
        return t

    def tick(self, _event: object = None) -> None:
        stamp = rospy.Time.now()
        t = self.sim_time(stamp)
        x, y, yaw = self.trajectory.pose(t)
        map_base = se2_matrix(x, y, yaw)
        odom_base = self.odom_map @ map_base
        self.tf.sendTransform(
            [
                to_transform(self.frames["map"], self.frames["odom"], self.map_odom, stamp),
                to_transform(self.frames["odom"], self.frames["base"], odom_base, stamp),
            ]
        )
        if self.ticks % self.scan_every == 0:
            self.publish_scan(stamp, t, map_base)
        if self.detect_every and self.ticks % self.detect_every == 0:
            self.publish_detections(stamp, t, map_base)
        self.ticks += 1
        if not self.done and not self.loop and t >= self.trajectory.duration:
            self.done = True
            self.done_pub.publish(Bool(True))
            rospy.loginfo("sim: trajectory finished after %.1f s of simulated time", t)

    def publish_scan(self, stamp: rospy.Time, t: float, map_base: np.ndarray) -> None:
        laser = map_base @ se2_matrix(self.laser_x, 0.0, 0.0)
        pose = (float(laser[0, 2]), float(laser[1, 2]), math.atan2(laser[1, 0], laser[0, 0]))
        c = self.lidar.config
        ranges = self.lidar.scan(self.world, pose, t)
        msg = laser_scan(
            stamp,
            self.frames["laser"],
            ranges,
            c.angle_min,
            c.angle_increment,
            c.range_min,
            c.range_max,
        )
        msg.scan_time = 1.0 / self.scan_rate
        self.scan_pub.publish(msg)

    def publish_detections(self, stamp: rospy.Time, t: float, map_base: np.ndarray) -> None:
        objects = self.world.objects_at(t)
        base_map = np.linalg.inv(map_base)
        xy = np.array([[o.x, o.y, 1.0] for o in objects]).reshape(-1, 3)
        in_base = (base_map @ xy.T).T[:, :2]
        near = np.hypot(in_base[:, 0], in_base[:, 1]) <= self.detection_range
        noisy = in_base + self.rng.normal(0.0, self.detection_noise, in_base.shape)
        kept = [o for o, k in zip(objects, near, strict=True) if k]
        self.detection_pub.publish(
            detection_array(
                stamp,
                self.frames["base"],
                noisy[near],
                np.full(len(kept), 0.9),
                np.array([o.truth_id for o in kept]),
                max(self.detection_noise**2, 1e-6),
                sizes=np.array([[o.size_x, o.size_y] for o in kept]).reshape(-1, 2),
                labels=[o.label for o in kept],
                class_ids=[self.class_ids.setdefault(o.label, len(self.class_ids)) for o in kept],
            )
        )


def main() -> None:
    rospy.init_node("sim")
    node = SimNode()
    rospy.Timer(rospy.Duration(1.0 / node.tf_rate), node.tick)
    rospy.spin()


if __name__ == "__main__":
    main()
