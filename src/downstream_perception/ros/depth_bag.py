"""Depth frames with camera poses (Open3D / Redwood trajectory format) to a bag the replay tool
reads, so a recorded depth sequence can be fused by the TSDF nodelet:

    python3 -m downstream_perception.ros.depth_bag DEPTH.npz TRAJECTORY.log BAG \\
        [--fx 525 --fy 525 --cx 319.5 --cy 239.5 --rate-hz 5]

DEPTH.npz holds `depth_mm`, a (frames, height, width) uint16 array in millimetres (0 = no
data). TRAJECTORY.log is the camera trajectory format of Open3D and the Redwood data sets: per
frame a line of three integers, then the 4 x 4 camera-to-world matrix (optical frame: z
forward), row by row. The bag holds tf `odom` <- `camera` at each frame's stamp,
`/depth/camera_info` and `/depth/image` (16UC1, REP-118); replay it with
`--tsdf <yaml> --tsdf-depth /depth` and a TSDF YAML whose `world_frame` is `odom`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import rosbag
import rospy
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage

from downstream_perception.ros.util import refuse_existing_output, transform_from_matrix
from downstream_perception.trajectory_log import read_trajectory_log

START_S = 100.0


def record_depth_bag(
    path: Path,
    depth_mm: np.ndarray,
    poses: list[np.ndarray],
    intrinsics: tuple[float, float, float, float],
    rate_hz: float = 5.0,
) -> None:
    """Writes the frames (uint16 mm, (frames, h, w)) with their poses into a bag at `path`."""
    if depth_mm.ndim != 3 or depth_mm.dtype != np.uint16:
        raise ValueError("depth_mm must be a (frames, height, width) uint16 array")
    if len(poses) != len(depth_mm):
        raise ValueError(f"{len(depth_mm)} depth frames but {len(poses)} poses")
    fx, fy, cx, cy = intrinsics
    height, width = depth_mm.shape[1:]
    with rosbag.Bag(str(path), "w") as bag:
        for k, (depth, pose) in enumerate(zip(depth_mm, poses, strict=True)):
            stamp = rospy.Time.from_sec(START_S + k / rate_hz)
            tf = transform_from_matrix("odom", "camera", stamp, pose)
            bag.write("/tf", TFMessage([tf]), stamp)
            info = CameraInfo()
            info.header.stamp, info.header.frame_id = stamp, "camera"
            info.width, info.height = width, height
            info.K = [fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0]
            image = Image()
            image.header = info.header
            image.height, image.width = height, width
            image.encoding, image.step, image.is_bigendian = "16UC1", width * 2, 0
            image.data = depth.astype("<u2").tobytes()
            later = stamp + rospy.Duration.from_sec(0.01)  # as a recorder receives them
            bag.write("/depth/camera_info", info, later)
            bag.write("/depth/image", image, later)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("depth", type=Path, help=".npz with depth_mm (frames, h, w) uint16")
    ap.add_argument("trajectory", type=Path, help="Open3D / Redwood trajectory .log")
    ap.add_argument("bag", type=Path)
    ap.add_argument("--overwrite", action="store_true", help="replace an existing bag")
    ap.add_argument("--fx", type=float, default=525.0, help="px (PrimeSense default)")
    ap.add_argument("--fy", type=float, default=525.0, help="px")
    ap.add_argument("--cx", type=float, default=319.5, help="px")
    ap.add_argument("--cy", type=float, default=239.5, help="px")
    ap.add_argument("--rate-hz", type=float, default=5.0, help="frame rate of the stamps")
    args = ap.parse_args(argv)
    refuse_existing_output(args.bag, args.overwrite, "depth_bag")
    with np.load(args.depth) as data:
        depth = data["depth_mm"]
    poses = read_trajectory_log(args.trajectory)
    record_depth_bag(args.bag, depth, poses, (args.fx, args.fy, args.cx, args.cy), args.rate_hz)
    print(f"depth_bag: {len(depth)} frames -> {args.bag}")


if __name__ == "__main__":
    main()
