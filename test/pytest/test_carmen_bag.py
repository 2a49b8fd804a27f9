"""pytest: a CARMEN laser log (the Radish 2-D lidar data sets) into a bag the replay tool reads:
scans, poses, the no-return reading and the laser offset, and malformed lines refused by number."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

rosbag = pytest.importorskip("rosbag")

from downstream_perception.ros import carmen_bag  # noqa: E402


def flaser(ranges: list[float], pose: tuple[float, float, float], stamp: float) -> str:
    values = " ".join(str(r) for r in ranges)
    x, y, th = pose
    return f"FLASER {len(ranges)} {values} {x} {y} {th} {x} {y} {th} {stamp} host {stamp}"


def write_log(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(["# CARMEN", "PARAM robot_frontlaser_offset 0.25 host 0", *lines]))
    return path


def test_scans_and_poses_reach_the_bag(tmp_path: Path) -> None:
    ranges = [1.0, 2.0, 81.83, 3.5]
    log = write_log(
        tmp_path / "a.log",
        [
            flaser(ranges, (0.0, 0.0, 0.0), 10.0),
            "ODOM 0 0 0 0 0 0 10.5 host 10.5",
            flaser(ranges, (1.0, 2.0, math.pi / 2), 11.0),
            flaser(ranges, (1.5, 2.0, math.pi / 2), 11.0),  # same stamp: skipped
        ],
    )
    scans, offset = carmen_bag.read_log(log)
    assert len(scans) == 3 and offset == 0.25
    assert carmen_bag.write_bag(scans, offset, tmp_path / "a.bag") == 2
    with rosbag.Bag(str(tmp_path / "a.bag")) as bag:
        msgs = {}
        for topic, msg, _t in bag.read_messages():
            msgs.setdefault(topic, []).append(msg)
    assert len(msgs["/scan"]) == 2 and len(msgs["/tf"]) == 2
    scan = msgs["/scan"][1]
    assert scan.header.stamp.to_sec() == pytest.approx(carmen_bag.START_S + 1.0)
    assert list(scan.ranges[:2]) == [1.0, 2.0] and math.isinf(scan.ranges[2])
    assert scan.angle_min == pytest.approx(-math.pi / 2)
    assert scan.angle_increment == pytest.approx(math.pi / 4)
    tf = msgs["/tf"][1].transforms[0]
    assert (tf.header.frame_id, tf.child_frame_id) == ("odom", "base_link")
    assert (tf.transform.translation.x, tf.transform.translation.y) == (1.0, 2.0)
    assert tf.transform.rotation.z == pytest.approx(math.sin(math.pi / 4))
    static = msgs["/tf_static"][0].transforms[0]
    assert static.child_frame_id == "laser" and static.transform.translation.x == 0.25


@pytest.mark.parametrize(
    "line",
    [
        "FLASER 3 1 2",
        "FLASER x 1 2 3",
        flaser([1.0, float("nan")], (0, 0, 0), 1.0),
        flaser([1.0, 2.0], (0, float("inf"), 0), 1.0),
    ],
)
def test_a_malformed_line_is_refused_by_number(tmp_path: Path, line: str) -> None:
    log = write_log(tmp_path / "bad.log", [flaser([1.0], (0, 0, 0), 0.5), line])
    with pytest.raises(carmen_bag.CarmenError, match="line 4"):
        carmen_bag.read_log(log)


def test_a_log_without_scans_is_refused(tmp_path: Path) -> None:
    with pytest.raises(carmen_bag.CarmenError, match="no FLASER"):
        carmen_bag.read_log(write_log(tmp_path / "empty.log", ["ODOM 0 0 0 0 0 0 1 h 1"]))


def test_an_existing_bag_is_kept_unless_overwrite_is_given(tmp_path: Path) -> None:
    log = write_log(tmp_path / "a.log", [flaser([1.0, 2.0], (0.0, 0.0, 0.0), 10.0)])
    bag = tmp_path / "a.bag"
    bag.write_bytes(b"precious")
    with pytest.raises(SystemExit, match="exists; pass --overwrite"):
        carmen_bag.main([str(log), str(bag)])
    assert bag.read_bytes() == b"precious"
    carmen_bag.main([str(log), str(bag), "--overwrite"])
    with rosbag.Bag(str(bag)) as b:
        assert b.get_message_count("/scan") == 1
    # Never through a symlink or onto something that is not a regular file.
    link = tmp_path / "link.bag"
    link.symlink_to(tmp_path / "elsewhere.bag")
    with pytest.raises(SystemExit, match="not a regular file"):
        carmen_bag.main([str(log), str(link), "--overwrite"])
    assert not (tmp_path / "elsewhere.bag").exists()
    with pytest.raises(SystemExit, match="not a regular file"):
        carmen_bag.main([str(log), str(tmp_path), "--overwrite"])
