"""A CARMEN laser log (the Radish / Freiburg 2-D lidar data sets: Intel Research Lab, ACES,
MIT CSAIL, ...) as a bag the replay tool reads, so a costmap can be built from real scans:

    python3 -m downstream_perception.ros.carmen_bag intel-corrected.log intel.bag
    python3 -m downstream_perception.replay intel.bag --config costmap.yaml --rate 0

Each FLASER line becomes a LaserScan on /scan (frame `laser`, 180 beams over 180 degrees from
-90 deg; a reading at or beyond the log's no-return range becomes +Inf, REP-117) and a /tf
odom <- base_link at the line's pose (the robot pose field; in the "corrected" logs that pose is
the scan-matched one). A static base_link <- laser carries the log's robot_frontlaser_offset.
Stamps are the log's ipc timestamps (s) shifted by START_S so that time 0 is never used. Other
lines (ODOM, PARAM, NEFF, ...) are read for the laser offset only.

Written here rather than taken from a library: no maintained Python package reads CARMEN logs
into ROS 1 bags, and the format is one whitespace-separated line per message."""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

START_S = 1000.0
NO_RETURN_M = 81.0  # SICK LMS: 81.83 (and up) is the "no return" reading in these logs


@dataclass
class FlaserLine:
    ranges_m: list[float]
    x_m: float
    y_m: float
    theta_rad: float
    stamp_s: float


class CarmenError(ValueError):
    """The log is not a CARMEN log this tool reads; the message names the line."""


def parse_flaser(fields: list[str], line_no: int) -> FlaserLine:
    """FLASER n r1..rn x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_ts."""
    try:
        n = int(fields[1])
        if not 0 < n <= 10_000 or len(fields) < 2 + n + 7:
            raise CarmenError(f"line {line_no}: FLASER with {n} readings has {len(fields)} fields")
        ranges = [float(v) for v in fields[2 : 2 + n]]
        x, y, theta = (float(v) for v in fields[2 + n : 5 + n])
        stamp = float(fields[8 + n])
    except (IndexError, ValueError) as e:
        if isinstance(e, CarmenError):
            raise
        raise CarmenError(f"line {line_no}: unreadable FLASER ({e})") from e
    values = [*ranges, x, y, theta, stamp]
    if not all(math.isfinite(v) for v in values):
        raise CarmenError(f"line {line_no}: FLASER holds a non-finite number")
    return FlaserLine(ranges, x, y, theta, stamp)


def read_log(path: Path) -> tuple[list[FlaserLine], float]:
    """The FLASER lines in file order, and the front laser's offset along x (m)."""
    scans, offset = [], 0.0
    with open(path, encoding="ascii", errors="replace") as f:
        for line_no, line in enumerate(f, 1):
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if fields[0] == "FLASER":
                scans.append(parse_flaser(fields, line_no))
            elif (
                fields[0] == "PARAM" and len(fields) >= 3 and fields[1] == "robot_frontlaser_offset"
            ):
                offset = float(fields[2])
    if not scans:
        raise CarmenError(f"{path}: no FLASER line")
    return scans, offset


def write_bag(scans: list[FlaserLine], laser_offset_m: float, out: Path) -> int:
    """The scans and their tf into `out`; returns the number of scans written (a scan whose
    stamp does not increase is skipped: the replay refuses a clock that goes back)."""
    import rosbag
    import rospy
    from tf2_msgs.msg import TFMessage

    from downstream_perception.ros.util import laser_scan, transform_stamped

    t0 = scans[0].stamp_s
    written, last = 0, -math.inf
    with rosbag.Bag(str(out), "w") as bag:
        start = rospy.Time.from_sec(START_S)
        static = transform_stamped("base_link", "laser", start, x=laser_offset_m)
        bag.write("/tf_static", TFMessage([static]), start)
        for s in scans:
            stamp_s = START_S + (s.stamp_s - t0)
            if stamp_s <= last:
                continue
            last = stamp_s
            stamp = rospy.Time.from_sec(stamp_s)
            tf = transform_stamped("odom", "base_link", stamp, x=s.x_m, y=s.y_m, yaw=s.theta_rad)
            bag.write("/tf", TFMessage([tf]), stamp)
            n = len(s.ranges_m)
            ranges = [r if r < NO_RETURN_M else math.inf for r in s.ranges_m]
            increment = math.pi / n
            msg = laser_scan(stamp, "laser", ranges, -math.pi / 2, increment, 0.0, NO_RETURN_M)
            bag.write("/scan", msg, stamp)
            written += 1
    return written


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("log", type=Path)
    ap.add_argument("bag", type=Path)
    ap.add_argument("--overwrite", action="store_true", help="replace an existing bag")
    args = ap.parse_args(argv)
    from downstream_perception.ros.util import refuse_existing_output

    refuse_existing_output(args.bag, args.overwrite, "carmen_bag")
    scans, offset = read_log(args.log)
    n = write_bag(scans, offset, args.bag)
    span = scans[-1].stamp_s - scans[0].stamp_s
    print(f"carmen_bag: {n} scans over {span:.0f} s into {args.bag}")


if __name__ == "__main__":
    main()
