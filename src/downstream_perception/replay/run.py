"""The nodelets on a private master, fed a bag on simulated time (rospy and roslaunch)."""

from __future__ import annotations

import math
import os
import subprocess
import sys
import tempfile
import time
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

import numpy as np

import downstream_perception as dp
from downstream_perception.replay import seam
from downstream_perception.replay.bag import TF_TOPICS, BagSummary, check, open_bag, summarize
from downstream_perception.replay.outputs import TrackLog
from downstream_perception.replay.pipeline import Pipeline, ReplayError
from downstream_perception.replay.progress import Progress

PACKAGE = "downstream_perception"
# The topics and services of the nodelets as the launch files name them.
COSTMAP_TOPIC = "/costmap/costmap"
TRACKS_TOPIC = "/tracker/tracks"
TSDF_SAVES = {
    "mesh": ("/tsdf/save_mesh", "mesh.ply"),
    "octomap": ("/tsdf/save_octomap", "octomap.bt"),
}


@dataclass
class ReplayOptions:
    rate: float = 4.0  # times real time; 0: as fast as the messages can be published
    settle_s: float = 2.0  # simulated seconds after the last message (tf filters, timers)
    timeout_s: float = 60.0  # for the nodelets to subscribe, and for the last costmap
    quiet: bool = False  # no progress bar
    overwrite: bool = False  # replace the outputs of an earlier replay in --out


@dataclass
class CostmapResult:
    grid: np.ndarray  # OccupancyGrid values, rows = y
    resolution: float
    origin: tuple[float, float]


@dataclass
class ReplayResult:
    wall_s: float
    messages: Counter[str]
    diagnostics: dict[str, str]
    costmap: CostmapResult | None = None
    tracks: TrackLog | None = None  # tracks.csv, written while the bag plays
    saved: dict[str, str] = field(default_factory=dict)  # what the TSDF nodelet wrote, or why not
    path_xy: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    seam: seam.SeamReport | None = None


def bag_tf(bag: Any, summary: BagSummary) -> Any:
    """A tf2 buffer holding the bag's whole /tf and /tf_static."""
    import rospy
    import tf2_ros

    buffer = tf2_ros.Buffer(cache_time=rospy.Duration(summary.duration_s + 60.0), debug=False)
    with warnings.catch_warnings():
        # The bag's messages are of the classes stored in it, not the installed ones; tf2_ros
        # warns about every transform although the fields are the same.
        warnings.simplefilter("ignore", UserWarning)
        tf_topics = [t for t in TF_TOPICS if t in summary.topics]
        for topic, msg, _t in bag.read_messages(topics=tf_topics):
            for tf in msg.transforms:
                if topic == "/tf_static":
                    buffer.set_transform_static(tf, "bag")
                else:
                    buffer.set_transform(tf, "bag")
    return buffer


def sampled_transforms(
    buffer: Any, target: str, source: str, summary: BagSummary, samples: int = 400
) -> tuple[np.ndarray, np.ndarray]:
    """target <- source at evenly spaced bag times: (times s, rows x y yaw) where tf has it."""
    import rospy
    import tf2_ros

    times, poses = [], []
    for t in np.linspace(summary.start_s, summary.end_s, samples):
        try:
            tf = buffer.lookup_transform(target, source, rospy.Time.from_sec(t))
        except tf2_ros.TransformException:
            continue
        q, p = tf.transform.rotation, tf.transform.translation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        times.append(t)
        poses.append((p.x, p.y, yaw))
    return np.array(times), np.array(poses).reshape(-1, 3)


def seam_report(buffer: Any, summary: BagSummary, target: str, robot: str) -> tuple[Any, Any]:
    """The robot's motion (for the map and the smear) and the seam health of the bag."""
    t, poses = sampled_transforms(buffer, target, robot, summary)
    motion = seam.RobotMotion(t, poses[:, :2], poses[:, 2])
    limits = dp.SeamLimits()
    inputs = seam.input_seams(summary.input_stamps_s, summary.transform_ages_s, motion, limits)
    # REP-105's names: the localisation correction is map <- odom.
    ct, corrections = np.zeros(0), np.zeros(0)
    if summary.tf_parents.get("odom") == "map":
        ct, c = sampled_transforms(buffer, "map", "odom", summary)
        corrections = np.linalg.norm(c[:, :2], axis=1)
    travelled = np.interp(ct, motion.t_s, motion.travelled_m()) if len(t) else np.zeros(len(ct))
    findings = seam.correction_findings(ct, corrections, travelled)
    return motion, seam.SeamReport(limits, inputs, ct, corrections, findings)


def launch_file(pipeline: Pipeline, out: Path) -> str:
    """One launch file: a manager and each capability's own launch file loading into it."""
    lines = [
        "<launch>",
        '  <node pkg="nodelet" type="nodelet" name="perception_manager" args="manager"/>',
    ]
    if pipeline.capability("tsdf"):
        lines.append(f'  <param name="/tsdf/output_dir" value={quoteattr(str(out.resolve()))}/>')
    for c in pipeline.capabilities:
        args = {"config": str(c.config.resolve()), "start_manager": "false", "bond": "false"}
        args.update(c.launch_args)
        lines.append(f'  <include file="$(find {PACKAGE})/launch/{c.name}.launch">')
        lines += [f"    <arg name={quoteattr(k)} value={quoteattr(v)}/>" for k, v in args.items()]
        lines.append("  </include>")
    return "\n".join(lines + ["</launch>", ""])


def replay(
    bag_path: Path, pipeline: Pipeline, out: Path, options: ReplayOptions
) -> tuple[BagSummary, ReplayResult]:
    """Checks the bag against the pipeline, then runs the nodelets on it; `out` is created
    only once the bag has passed the checks."""
    from downstream_perception.ros.processes import free_port, stop_process

    bag = open_bag(bag_path)
    try:
        summary = summarize(bag, bag_path, [i.topic for i in pipeline.inputs])
        problems = check(summary, pipeline)
        if problems:
            raise ReplayError("; ".join(problems))
        first = pipeline.capabilities[0]
        motion, seam_health = seam_report(
            bag_tf(bag, summary), summary, first.frame, pipeline.robot_frame
        )
        out.mkdir(parents=True, exist_ok=True)
        port = free_port()
        os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
        with open(os.devnull, "w") as log, tempfile.TemporaryDirectory() as tmp:
            launch = Path(tmp) / "replay.launch"
            launch.write_text(launch_file(pipeline, out))
            procs = [subprocess.Popen(["roscore", "-p", str(port)], stdout=log, stderr=log)]
            try:
                run = NodeletRun(bag, summary, pipeline, out, options)
                run.start(launch, port, procs, log)
                result = run.play()
                result.path_xy, result.seam = motion.xy, seam_health
                return summary, result
            finally:
                for proc in reversed(procs):
                    stop_process(proc)
    finally:
        bag.close()


class NodeletRun:
    """The nodelets on a private master, fed the bag on simulated time."""

    def __init__(
        self, bag: Any, summary: BagSummary, pipeline: Pipeline, out: Path, options: ReplayOptions
    ) -> None:
        self.bag, self.summary, self.pipeline, self.options = bag, summary, pipeline, options
        self.out = out
        self.topics = [i.topic for i in pipeline.inputs if i.topic in summary.topics]
        self.topics += [t for t in TF_TOPICS if t in summary.topics]
        self.diagnostics: dict[str, str] = {}
        self.tracks: TrackLog | None = None
        self.costmap: Any = None

    def start(self, launch: Path, port: int, procs: list[Any], log: Any) -> None:
        import rosgraph
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray
        from rosgraph_msgs.msg import Clock

        deadline = time.monotonic() + 30.0
        while not rosgraph.is_master_online():
            if time.monotonic() > deadline:
                raise ReplayError("the private ROS master did not start")
            time.sleep(0.2)
        rospy.set_param("/use_sim_time", True)
        procs.append(
            subprocess.Popen(["roslaunch", "-p", str(port), str(launch)], stdout=log, stderr=log)
        )
        self.launch = procs[-1]
        rospy.init_node("replay", anonymous=True, disable_signals=True)
        self.clock = rospy.Publisher("/clock", Clock, queue_size=10)
        self.clock.publish(Clock(rospy.Time.from_sec(self.summary.start_s)))
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diagnostics, queue_size=50)
        if self.pipeline.capability("costmap"):
            from downstream_perception.ros.costmap_client import CostmapClient

            self.costmap = CostmapClient(COSTMAP_TOPIC)
        if self.pipeline.capability("tracker"):
            from downstream_perception.msg import TrackedObjectArray

            self.tracks = TrackLog(self.out / "tracks.csv")
            rospy.Subscriber(TRACKS_TOPIC, TrackedObjectArray, self._on_tracks, queue_size=1000)
        self.publishers = self._subscribed_publishers()

    def _on_diagnostics(self, msg: Any) -> None:
        for status in msg.status:
            if any(c.name in status.name for c in self.pipeline.capabilities):
                self.diagnostics.update({f"{status.name}: {v.key}": v.value for v in status.values})

    def _on_tracks(self, msg: Any) -> None:
        self.tracks.add(msg.header.stamp.to_sec(), msg.tracks)

    def _subscribed_publishers(self) -> dict[str, Any]:
        """A publisher per topic, of the bag's message class, once a nodelet subscribes."""
        import rospy

        publishers: dict[str, Any] = {}
        for topic, msg, _t in self.bag.read_messages(topics=self.topics):
            if topic not in publishers:
                latched = topic == "/tf_static"
                publishers[topic] = rospy.Publisher(
                    topic, type(msg), queue_size=1000, latch=latched
                )
            if len(publishers) == len(self.topics):
                break
        deadline = time.monotonic() + self.options.timeout_s
        for topic, pub in publishers.items():
            while pub.get_num_connections() == 0:
                if time.monotonic() > deadline or self.launch.poll() is not None:
                    raise ReplayError(
                        f"no nodelet subscribed to {topic} within {self.options.timeout_s:.0f} s"
                    )
                time.sleep(0.1)
        return publishers

    def _publish_clock(self, t_s: float) -> None:
        import rospy
        from rosgraph_msgs.msg import Clock

        self.clock.publish(Clock(rospy.Time.from_sec(t_s)))

    def play(self) -> ReplayResult:
        rate, s = self.options.rate, self.summary
        progress = Progress(s.duration_s, None if self.options.quiet else sys.stderr)
        wall0 = time.monotonic()
        last_clock = -math.inf
        for topic, msg, t in self.bag.read_messages(topics=self.topics):
            now_s = t.to_sec()
            ahead = (now_s - s.start_s) / rate - (time.monotonic() - wall0) if rate > 0 else 0.0
            if ahead > 0:
                time.sleep(ahead)
            if now_s > last_clock:
                self._publish_clock(now_s)
                last_clock = now_s
            self.publishers[topic].publish(msg)
            progress.update(topic, now_s - s.start_s)
        # Let the last messages through the tf filters and the update and publish timers run.
        steps = max(1, int(self.options.settle_s / 0.05))
        for k in range(1, steps + 1):
            self._publish_clock(s.end_s + k * 0.05)
            time.sleep(0.05 / max(rate, 1.0))
        wall_s = time.monotonic() - wall0
        progress.finish()
        result = ReplayResult(wall_s, progress.counts, {})
        if self.costmap is not None:
            result.costmap = self._final_costmap()
        if self.pipeline.capability("tsdf"):
            result.saved = self._save_tsdf()
        # One more diagnostics round: the nodelets publish theirs on simulated time (at most
        # once per simulated second), so the clock moves on by more than that.
        end_s = s.end_s + steps * 0.05
        for k in range(1, 25):
            self._publish_clock(end_s + k * 0.05)
            time.sleep(0.05)
        result.diagnostics = dict(self.diagnostics)
        if self.tracks is not None:
            self.tracks.close()
        result.tracks = self.tracks
        return result

    def _final_costmap(self) -> CostmapResult:
        # The costmap published after the settle time holds every message: wait for a change
        # sent after it (full grid or update), or for 3 s of quiet once a grid has come.
        settled = time.time()
        deadline = time.monotonic() + self.options.timeout_s
        while time.monotonic() < deadline:
            quiet = time.time() - settled > 3.0
            if self.costmap.received and (self.costmap.last_change_wall > settled or quiet):
                break
            self._publish_clock(self.summary.end_s + self.options.settle_s)
            time.sleep(0.1)
        if not self.costmap.received:
            raise ReplayError("the costmap nodelet published no costmap (publish_frequency 0?)")
        info = self.costmap.message().info
        return CostmapResult(self.costmap.grid(), float(info.resolution), self.costmap.origin())

    def _save_tsdf(self) -> dict[str, str]:
        import rospy

        from downstream_perception.srv import SaveMap

        saved = {}
        for what, (service, name) in TSDF_SAVES.items():
            try:
                rospy.wait_for_service(service, timeout=self.options.timeout_s)
                save = rospy.ServiceProxy(service, SaveMap)
                reply = save(path=name, overwrite=self.options.overwrite)
            except (rospy.ROSException, rospy.ServiceException) as e:
                saved[what] = f"not saved: {e}"
                continue
            saved[what] = reply.written_path if reply.success else f"not saved: {reply.message}"
        return saved
