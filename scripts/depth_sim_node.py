#!/usr/bin/env python3
"""Depth camera simulator node: the analytic room (sim.depth_camera.room_scene) seen from ~frames
poses on a circle, published at ~rate_hz.

Each frame: tf ~world_frame -> ~camera_frame (optical convention) at the frame's stamp, then
`depth/camera_info` and `depth/image` (32FC1 metres, NaN = no hit; or 16UC1 millimetres, 0 = no
hit, with ~encoding: 16UC1). After the last frame, latched std_msgs/Bool(True) on `~done`.
With ~remove_box_after: n (>= 0), frames n and later render the room without its box: an object
that moved away, for free-space carving. ~blind_frames: [k, ...] are published with every pixel
+Inf (32FC1: no return, as through a covered lens), which carving must not take as free space.
With ~trajectory: corridor the camera walks down an endless corridor instead (sim.depth_camera.
corridor_scene, ~speed_mps, default 1 m/s, for ~frames frames: a long path for soaks of the
distance eviction); the corridor repeats every 4 m, so one period is rendered before the first
frame and replayed shifted (~depth_noise_m is then added per frame; ~remove_box_after is ignored).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import rospy
import tf2_ros
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import Bool, Header

from downstream_perception.ros.util import transform_from_matrix
from downstream_perception.sim.depth_camera import (
    CORRIDOR_PERIOD_M,
    DepthCamera,
    circle_poses,
    corridor_poses,
    corridor_scene,
    room_scene,
)


def camera_info(cam: DepthCamera, header: Header) -> CameraInfo:
    info = CameraInfo()
    info.header = header
    info.width, info.height = cam.width, cam.height
    info.distortion_model = "plumb_bob"
    info.D = [0.0] * 5
    info.K = [cam.fx, 0.0, cam.cx, 0.0, cam.fy, cam.cy, 0.0, 0.0, 1.0]
    info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.P = [cam.fx, 0.0, cam.cx, 0.0, 0.0, cam.fy, cam.cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return info


def depth_image(depth: np.ndarray, header: Header, encoding: str) -> Image:
    msg = Image()
    msg.header = header
    msg.height, msg.width = depth.shape
    msg.encoding = encoding
    msg.is_bigendian = 0
    if encoding == "16UC1":
        data = np.nan_to_num(np.rint(depth * 1000.0), nan=0.0).clip(0, 65535).astype("<u2")
    else:
        data = depth.astype("<f4")
    msg.step = msg.width * data.itemsize
    msg.data = data.tobytes()
    return msg


Frame = tuple[np.ndarray, np.ndarray]  # (depth image, T_world_camera)


def room_frames(
    cam: DepthCamera, frames: int, remove_box_after: int, noise: float, rng: np.random.Generator
) -> Callable[[int], Frame]:
    """Frame k of `frames` on the circle around the room, rendered when asked for."""
    scene = room_scene()
    without_box = room_scene()
    without_box.boxes = without_box.boxes[1:]  # boxes[0] is the box; the table top stays
    poses = circle_poses(frames)

    def frame(k: int) -> Frame:
        seen = without_box if 0 <= remove_box_after <= k else scene
        return cam.render(seen, poses[k], depth_noise_m=noise, rng=rng), poses[k]

    return frame


def corridor_frames(
    cam: DepthCamera, speed_mps: float, rate_hz: float, noise: float, rng: np.random.Generator
) -> Callable[[int], Frame]:
    """Frame k walking down the corridor at speed_mps: one period rendered now, then replayed
    shifted by whole periods (the corridor repeats, so the images are those of the endless
    corridor)."""
    if not np.isfinite(speed_mps) or speed_mps <= 0.0:
        rospy.logerr("depth_sim: ~speed_mps must be positive, got %s; using 1.0", speed_mps)
        speed_mps = 1.0
    n = max(1, round(CORRIDOR_PERIOD_M * rate_hz / speed_mps))
    poses = corridor_poses(n)
    scene = corridor_scene()
    rospy.loginfo("depth_sim: rendering the corridor's %d frames per %.0f m", n, CORRIDOR_PERIOD_M)
    depths = [cam.render(scene, T) for T in poses]

    def frame(k: int) -> Frame:
        T = poses[k % n].copy()
        T[0, 3] += (k // n) * CORRIDOR_PERIOD_M
        depth = depths[k % n]
        if noise > 0.0:
            depth = (depth + rng.normal(0.0, noise, depth.shape)).astype(np.float32)
        return depth, T

    return frame


def main() -> None:
    rospy.init_node("depth_sim")
    p = rospy.get_param
    frames = int(p("~frames", 30))
    rate_hz = float(p("~rate_hz", 5.0))
    world = str(p("~world_frame", "odom"))
    optical = str(p("~camera_frame", "depth_optical"))
    encoding = str(p("~encoding", "32FC1"))
    noise = float(p("~depth_noise_m", 0.0))
    cam = DepthCamera.vga() if p("~resolution", "qvga") == "vga" else DepthCamera()
    if encoding not in ("32FC1", "16UC1"):
        rospy.logerr("depth_sim: ~encoding must be 32FC1 or 16UC1; using 32FC1")
        encoding = "32FC1"
    trajectory = str(p("~trajectory", "circle"))
    if trajectory not in ("circle", "corridor"):
        rospy.logerr("depth_sim: ~trajectory must be circle or corridor; using circle")
        trajectory = "circle"
    # Frames seen through a covered lens: every pixel +Inf (no return, REP-118).
    blind_frames = {int(k) for k in p("~blind_frames", [])}
    rng = np.random.default_rng(int(p("~seed", 0)))
    if trajectory == "corridor":
        frame_at = corridor_frames(cam, float(p("~speed_mps", 1.0)), rate_hz, noise, rng)
    else:
        frame_at = room_frames(cam, frames, int(p("~remove_box_after", -1)), noise, rng)
    tf = tf2_ros.TransformBroadcaster()
    info_pub = rospy.Publisher("depth/camera_info", CameraInfo, queue_size=5)
    image_pub = rospy.Publisher("depth/image", Image, queue_size=5)
    done = rospy.Publisher("~done", Bool, queue_size=1, latch=True)
    rospy.sleep(float(p("~start_delay_s", 2.0)))  # let subscribers connect
    rate = rospy.Rate(rate_hz)
    for k in range(frames):
        if rospy.is_shutdown():
            return
        depth, T = frame_at(k)
        if k in blind_frames:
            depth = np.full_like(depth, np.inf)
        stamp = rospy.Time.now()
        tf.sendTransform(transform_from_matrix(world, optical, stamp, T))
        header = Header(stamp=stamp, frame_id=optical)
        info_pub.publish(camera_info(cam, header))
        image_pub.publish(depth_image(depth, header, encoding))
        rate.sleep()
    done.publish(Bool(data=True))
    rospy.spin()


if __name__ == "__main__":
    main()
