"""Bags recorded from the simulators with the rosbag API, to try the replay tool (and to test
it) without a robot:

    python3 -m downstream_perception.ros.sim_bags aisle aisle.bag      # lidar, tf (costmap)
    python3 -m downstream_perception.ros.sim_bags objects objects.bag  # detections, tf (tracker)
    python3 -m downstream_perception.ros.sim_bags room room.bag        # depth images, tf (TSDF)

Stamps start at START_S (s); record times equal the stamps (detections and images 1-10 ms
later, as a recorder receives them)."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np
import rosbag
import rospy
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

from downstream_perception.planar import se2_matrix
from downstream_perception.ros.util import (
    detection_array,
    laser_scan,
    transform_from_matrix,
    transform_stamped,
)
from downstream_perception.sim import (
    Lidar,
    LidarConfig,
    ObjectScene,
    SceneConfig,
    aisle_drive,
    warehouse_aisle,
)
from downstream_perception.sim.depth_camera import DepthCamera, circle_poses, room_scene

START_S = 100.0


def record_aisle_bag(
    path: Path,
    duration_s: float = 8.0,
    scan_topic: str = "/scan",
    with_tf: bool = True,
    tf_jump_at_s: float | None = None,
) -> Path:
    """The robot drives the warehouse aisle at 1 m/s: scans at 10 Hz (frame laser), tf
    map <- odom <- base_link at 50 Hz and a static base_link <- laser."""
    world, drive = warehouse_aisle(), aisle_drive(1.0)
    lidar = Lidar(LidarConfig(num_beams=360, range_max=30.0, noise_std_m=0.01, seed=3))
    map_odom = se2_matrix(0.5, -0.2, 0.05)
    odom_map = np.linalg.inv(map_odom)
    with rosbag.Bag(str(path), "w") as bag:
        start = rospy.Time.from_sec(START_S)
        if with_tf:
            static = transform_stamped("base_link", "laser", start, x=0.0, z=0.2)
            bag.write("/tf_static", TFMessage([static]), start)
        for k in range(int(duration_s * 50) + 1):
            t = k / 50.0
            stamp_s = START_S + t
            if tf_jump_at_s is not None and t >= tf_jump_at_s:
                stamp_s -= 30.0  # the clock went back: a looped recording
            stamp = rospy.Time.from_sec(stamp_s)
            x, y, yaw = drive.pose(t)
            odom_base = odom_map @ se2_matrix(x, y, yaw)
            if with_tf:
                tfs = [
                    transform_stamped("map", "odom", stamp, x=0.5, y=-0.2, yaw=0.05),
                    transform_stamped(
                        "odom",
                        "base_link",
                        stamp,
                        x=odom_base[0, 2],
                        y=odom_base[1, 2],
                        yaw=math.atan2(odom_base[1, 0], odom_base[0, 0]),
                    ),
                ]
                bag.write("/tf", TFMessage(tfs), rospy.Time.from_sec(START_S + t))
            if k % 5 == 0:
                c = lidar.config
                ranges = lidar.scan(world, (x, y, yaw), t)
                msg = laser_scan(
                    stamp, "laser", ranges, c.angle_min, c.angle_increment, c.range_min, c.range_max
                )
                msg.scan_time = 0.1
                bag.write(scan_topic, msg, rospy.Time.from_sec(START_S + t))
    return path


def record_objects_bag(path: Path, frames: int = 150, robot_speed: float = 0.5) -> dict:
    """The object simulator's scene (sim.ObjectScene, 10 Hz) seen from a robot driving along odom
    x: detections in base_link, tf odom <- base_link. Returns the truth per stamp (s)."""
    config = SceneConfig(num_objects=20, rate_hz=10.0, seed=4)
    scene = ObjectScene(config)
    truth = {}
    with rosbag.Bag(str(path), "w") as bag:
        for _ in range(frames):
            f = scene.step()
            t = START_S + f.stamp
            stamp = rospy.Time.from_sec(t)
            robot_x = robot_speed * f.stamp
            tf = transform_stamped("odom", "base_link", stamp, x=robot_x)
            bag.write("/tf", TFMessage([tf]), stamp)
            in_base = f.positions - np.array([robot_x, 0.0])
            msg = detection_array(
                stamp, "base_link", in_base, f.scores, f.detection_truth, config.noise_std_m**2
            )
            bag.write("/detections", msg, stamp + rospy.Duration.from_sec(0.001))
            truth[round(t, 6)] = (f.truth_ids[f.visible], f.truth_positions[f.visible])
    return truth


def record_room_bag(path: Path, frames: int = 12) -> None:
    """The analytic room (sim.depth_camera.room_scene) seen at 160 x 120 from poses on a circle,
    5 Hz: tf odom <- camera (optical), depth/camera_info and depth/image (32FC1, NaN no hit)."""
    cam = DepthCamera(160, 120, 131.25, 131.25, 79.5, 59.5)
    scene, poses = room_scene(), circle_poses(frames)
    with rosbag.Bag(str(path), "w") as bag:
        for k, pose in enumerate(poses):
            stamp = rospy.Time.from_sec(START_S + 0.2 * k)
            bag.write(
                "/tf", TFMessage([transform_from_matrix("odom", "camera", stamp, pose)]), stamp
            )
            depth = cam.render(scene, pose)
            info = CameraInfo()
            info.header.stamp, info.header.frame_id = stamp, "camera"
            info.width, info.height = cam.width, cam.height
            info.K = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
            image = Image()
            image.header = info.header
            image.height, image.width = depth.shape
            image.encoding, image.step = "32FC1", cam.width * 4
            image.data = depth.astype("<f4").tobytes()
            later = stamp + rospy.Duration.from_sec(0.01)
            bag.write("/depth/camera_info", info, later)
            bag.write("/depth/image", image, later)


RECORDERS = {"aisle": record_aisle_bag, "objects": record_objects_bag, "room": record_room_bag}


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", choices=sorted(RECORDERS))
    ap.add_argument("bag", type=Path)
    args = ap.parse_args(argv)
    RECORDERS[args.scene](args.bag)
    print(f"sim_bags: wrote {args.bag}")


if __name__ == "__main__":
    main()
