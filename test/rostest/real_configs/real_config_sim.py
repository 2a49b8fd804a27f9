#!/usr/bin/env python3
"""Simulator for a real move_base costmap pair (move_base_config.build_scene): the static map
(latched nav_msgs/OccupancyGrid on every static layer's map_topic, frame map), tf map -> odom ->
<robot_base_frame> -> one frame per sensor, and on each observation source's topic its data_type
(LaserScan, PointCloud2 or PointCloud) from a noise-free 720-beam lidar over the same walls plus
two boxes the map lacks.

Parameters (global, shared with the test): /real_config/{common,global,local,global_ns,local_ns,
extra}. Topic ~robot_pose (geometry_msgs/Pose2D, map frame) moves the robot.
"""

from __future__ import annotations

import threading

import numpy as np
import rospy
import tf2_ros
from geometry_msgs.msg import Point32, Pose2D
from move_base_config import Scene, build_scene, load_pair_from
from nav_msgs.msg import OccupancyGrid
from sensor_msgs.msg import LaserScan, PointCloud, PointCloud2, PointField

from downstream_perception.ros.util import laser_scan, transform_stamped
from downstream_perception.sim import Lidar, LidarConfig, World

BEAMS = 720
RANGE_MAX_M = 30.0


def load_scene() -> tuple[Scene, dict]:
    tree = load_pair_from(rospy.get_param)
    return build_scene(tree), tree


def occupancy_grid(scene: Scene) -> OccupancyGrid:
    msg = OccupancyGrid()
    msg.header.frame_id = "map"
    msg.header.stamp = rospy.Time.now()
    msg.info.map_load_time = msg.header.stamp
    msg.info.resolution = scene.map_resolution
    msg.info.height, msg.info.width = scene.map_cells.shape
    msg.info.origin.position.x, msg.info.origin.position.y = scene.map_origin
    msg.info.origin.orientation.w = 1.0
    msg.data = scene.map_cells.ravel().tolist()
    return msg


def cloud2(stamp: rospy.Time, frame: str, xyz: np.ndarray) -> PointCloud2:
    """An unorganised x, y, z FLOAT32 cloud."""
    msg = PointCloud2()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.height, msg.width = 1, len(xyz)
    msg.fields = [
        PointField(name=n, offset=4 * k, datatype=PointField.FLOAT32, count=1)
        for k, n in enumerate("xyz")
    ]
    msg.is_bigendian = False
    msg.point_step = 12
    msg.row_step = 12 * len(xyz)
    msg.is_dense = True
    msg.data = np.ascontiguousarray(xyz, dtype=np.float32).tobytes()
    return msg


def cloud1(stamp: rospy.Time, frame: str, xyz: np.ndarray) -> PointCloud:
    msg = PointCloud()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.points = [Point32(float(x), float(y), float(z)) for x, y, z in xyz]
    return msg


class RealConfigSim:
    def __init__(self) -> None:
        self.scene, _ = load_scene()
        s = self.scene
        self.world = World(segments=s.world_segments())
        self.lidar = Lidar(
            LidarConfig(num_beams=BEAMS, range_max=RANGE_MAX_M, noise_std_m=0.0, range_min=0.05)
        )
        self._lock = threading.Lock()
        self.pose = s.start
        self.tf = tf2_ros.TransformBroadcaster()
        self.static_tf = tf2_ros.StaticTransformBroadcaster()
        now = rospy.Time.now()
        self.static_tf.sendTransform(
            [transform_stamped(s.base_frame, spec.frame, now, z=spec.height) for spec in s.sensors]
        )
        grid = occupancy_grid(s)
        self.map_pubs = [
            rospy.Publisher(topic, OccupancyGrid, queue_size=1, latch=True)
            for topic in s.map_topics
        ]
        for pub in self.map_pubs:
            pub.publish(grid)
        kinds = {"LaserScan": LaserScan, "PointCloud2": PointCloud2, "PointCloud": PointCloud}
        self.sensor_pubs = [
            (spec, rospy.Publisher(spec.topic, kinds.get(spec.data_type, PointCloud), queue_size=5))
            for spec in s.sensors
        ]
        rospy.Subscriber("~robot_pose", Pose2D, self._on_pose, queue_size=1)
        rospy.loginfo(
            "real_config_sim: map %dx%d at %.3f m on %s, near box %.2f m, far box %.2f m, "
            "sensors %s",
            grid.info.width,
            grid.info.height,
            s.map_resolution,
            s.map_topics,
            s.near.cx - s.near.half,
            float(np.hypot(s.far.cx, s.far.cy)),
            [(x.topic, x.data_type, x.frame, round(x.height, 3)) for x in s.sensors],
        )

    def _on_pose(self, msg: Pose2D) -> None:
        with self._lock:
            self.pose = (msg.x, msg.y)

    def step(self) -> None:
        s = self.scene
        with self._lock:
            x, y = self.pose
        stamp = rospy.Time.now()
        ox, oy = s.odom_in_map
        self.tf.sendTransform(
            [
                transform_stamped("map", "odom", stamp, x=ox, y=oy),
                transform_stamped("odom", s.base_frame, stamp, x=x - ox, y=y - oy),
            ]
        )
        ranges = self.lidar.scan(self.world, (x, y, 0.0))
        angles = self.lidar.angles()
        hit = np.isfinite(ranges)
        xyz = np.stack(
            [
                ranges[hit] * np.cos(angles[hit]),
                ranges[hit] * np.sin(angles[hit]),
                np.zeros(hit.sum()),
            ],
            axis=1,
        )
        cfg = self.lidar.config
        for spec, pub in self.sensor_pubs:
            if spec.data_type == "LaserScan":
                msg = laser_scan(
                    stamp,
                    spec.frame,
                    ranges,
                    cfg.angle_min,
                    cfg.angle_increment,
                    cfg.range_min,
                    cfg.range_max,
                )
            elif spec.data_type == "PointCloud2":
                msg = cloud2(stamp, spec.frame, xyz)
            else:
                msg = cloud1(stamp, spec.frame, xyz)
            pub.publish(msg)


def main() -> None:
    rospy.init_node("real_config_sim")
    sim = RealConfigSim()
    rate = rospy.Rate(10.0)
    while not rospy.is_shutdown():
        sim.step()
        try:
            rate.sleep()
        except rospy.ROSInterruptException:
            break


if __name__ == "__main__":
    main()
