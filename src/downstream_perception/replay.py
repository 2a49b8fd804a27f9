"""Replay a recorded bag through the costmap nodelet and collect what it made (for now the
costmap; the TSDF and the tracker follow).

    rosrun downstream_perception replay.py my.bag --config cfg/costmap.yaml --out out/
    python3 -m downstream_perception.replay my.bag --config cfg/costmap.yaml --out out/

The same nodelet with the same YAML as on the robot (``launch/costmap.launch``), on simulated
time taken from the bag: a private ROS master, ``/use_sim_time``, and the bag's messages published
in record order with ``/clock`` advanced to each one's record time, at ``--rate`` times real time.
Writes the final costmap as a map_server map (PGM + YAML, which the StaticLayer loads) and a
PNG with the robot's path, and a report (Markdown, and HTML with the images inline).

A bag that cannot be replayed (unreadable or unindexed, none of the configured topics, no tf
joining the global frame to the robot and the sensors, a clock that jumps back) fails before
anything starts, with a message and exit status 2; so does a replay in which the nodelet never
subscribes or publishes no costmap.
"""

from __future__ import annotations

import argparse
import base64
import html
import math
import os
import subprocess
import sys
import time
import warnings
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

PACKAGE = "downstream_perception"
TF_TOPICS = ("/tf", "/tf_static")
# A stamp that goes back by more than this between two /tf messages of the same child frame is a
# clock jump (a looped bag, a restarted simulator), not reordering.
CLOCK_JUMP_S = 1.0
# map_server's thresholds (map_saver --occ 65 --free 25; the YAML's occupied_thresh 0.65 and
# free_thresh 0.196) and its grey levels.
OCCUPIED_MIN, FREE_MAX = 65, 25
PGM_FREE, PGM_OCCUPIED, PGM_UNKNOWN = 254, 0, 205


class ReplayError(Exception):
    """The bag cannot be replayed with this configuration; the message says why."""


# ------------------------------------------------------------------- the costmap configuration
@dataclass
class Input:
    """One observation source of the costmap configuration."""

    layer: str
    source: str
    topic: str
    data_type: str


@dataclass
class CostmapSetup:
    global_frame: str
    robot_frame: str
    inputs: list[Input]


def costmap_setup(config: dict[str, Any]) -> CostmapSetup:
    """The frames and the observation sources' topics of a costmap YAML (ours or costmap_2d's:
    sources under each obstacle layer's namespace, or at the top level before Hydro). Relative
    topics resolve at the root, where the costmap launch file runs the nodelet."""
    if not isinstance(config, dict):
        raise ReplayError("the costmap configuration is not a YAML mapping")
    namespaces = [config] + [v for v in config.values() if isinstance(v, dict)]
    inputs = []
    for ns in namespaces:
        names = ns.get("observation_sources")
        if not isinstance(names, str):
            continue
        layer = next((k for k, v in config.items() if v is ns), "")
        for name in names.split():
            source = ns.get(name, {})
            if not isinstance(source, dict):
                continue
            topic = str(source.get("topic", name))
            data_type = str(source.get("data_type", "PointCloud"))  # costmap_2d's default
            inputs.append(
                Input(layer, name, topic if topic.startswith("/") else "/" + topic, data_type)
            )
    if not inputs:
        raise ReplayError("the configuration names no observation_sources: nothing to replay")
    return CostmapSetup(
        str(config.get("global_frame", "map")),
        str(config.get("robot_base_frame", "base_link")),
        inputs,
    )


# ------------------------------------------------------------------- what the bag holds
@dataclass
class BagSummary:
    path: Path
    start_s: float
    end_s: float
    topics: dict[str, tuple[str, int]]  # topic -> (type, count)
    frames: dict[str, str] = field(default_factory=dict)  # input topic -> its header frame_id
    tf_parents: dict[str, str] = field(default_factory=dict)  # child -> parent, /tf and /tf_static
    clock_jumps: list[str] = field(default_factory=list)
    transform_ages_s: dict[str, list[float]] = field(default_factory=dict)

    @property
    def duration_s(self) -> float:
        return max(0.0, self.end_s - self.start_s)


def open_bag(path: Path) -> Any:
    import rosbag

    if not path.is_file():
        raise ReplayError(f"{path}: no such file")
    try:
        return rosbag.Bag(str(path), "r")
    except rosbag.ROSBagUnindexedException as e:
        raise ReplayError(
            f"{path}: the bag is not indexed (a recording cut short?): run 'rosbag reindex' on a "
            f"copy first ({e})"
        ) from e
    except (rosbag.ROSBagException, OSError, ValueError) as e:
        raise ReplayError(f"{path}: not a readable bag: {e}") from e


def summarize(bag: Any, path: Path, input_topics: list[str]) -> BagSummary:
    """One pass over the bag: topics, the tf tree, the inputs' frames, clock jumps, and each
    input's transform age (its stamp minus the newest /tf stamp recorded before it)."""
    info = bag.get_type_and_topic_info().topics
    topics = {t: (i.msg_type, int(i.message_count)) for t, i in info.items()}
    summary = BagSummary(path, bag.get_start_time(), bag.get_end_time(), topics)
    wanted = [t for t in input_topics if t in topics] + [t for t in TF_TOPICS if t in topics]
    last_child_stamp: dict[str, float] = {}
    newest_tf_s = -math.inf
    try:
        for topic, msg, _t in bag.read_messages(topics=wanted):
            if topic in TF_TOPICS:
                for tf in msg.transforms:
                    child, stamp = tf.child_frame_id.lstrip("/"), tf.header.stamp.to_sec()
                    summary.tf_parents[child] = tf.header.frame_id.lstrip("/")
                    if topic == "/tf":
                        before = last_child_stamp.get(child)
                        if before is not None and stamp < before - CLOCK_JUMP_S:
                            summary.clock_jumps.append(
                                f"/tf {child} goes back {before - stamp:.1f} s (from {before:.3f} "
                                f"to {stamp:.3f})"
                            )
                        last_child_stamp[child] = stamp
                        newest_tf_s = max(newest_tf_s, stamp)
            else:
                summary.frames.setdefault(topic, msg.header.frame_id.lstrip("/"))
                if math.isfinite(newest_tf_s):
                    summary.transform_ages_s.setdefault(topic, []).append(
                        msg.header.stamp.to_sec() - newest_tf_s
                    )
    except Exception as e:  # rosbag raises several types for damaged chunks
        raise ReplayError(f"{path}: reading the bag failed: {type(e).__name__}: {e}") from e
    return summary


def tf_root(frame: str, parents: dict[str, str]) -> tuple[str, list[str]]:
    chain = [frame]
    while chain[-1] in parents and len(chain) < 100:
        chain.append(parents[chain[-1]])
    return chain[-1], chain


def check(summary: BagSummary, setup: CostmapSetup) -> list[str]:
    """Why this bag cannot feed this costmap; empty when it can."""
    problems = []
    present = [i for i in setup.inputs if i.topic in summary.topics]
    expected_type = {
        "LaserScan": "sensor_msgs/LaserScan",
        "PointCloud2": "sensor_msgs/PointCloud2",
        "PointCloud": "sensor_msgs/PointCloud",
    }
    for i in present:
        kind = summary.topics[i.topic][0]
        if expected_type.get(i.data_type, kind) != kind:
            problems.append(
                f"{i.topic} carries {kind}, but source '{i.source}' of layer '{i.layer}' has "
                f"data_type {i.data_type} ({expected_type[i.data_type]})"
            )
    if not present:
        listed = ", ".join(sorted(summary.topics)) or "none"
        wanted = ", ".join(f"{i.topic} ({i.source})" for i in setup.inputs)
        problems.append(
            f"none of the configured topics is in the bag (wanted {wanted}; the bag has {listed})"
        )
    if not any(t in summary.topics for t in TF_TOPICS):
        problems.append("the bag has no /tf or /tf_static: nothing places the sensors in the map")
    else:
        root, _ = tf_root(setup.global_frame, summary.tf_parents)
        frames = [setup.robot_frame] + [
            summary.frames[i.topic] for i in present if i.topic in summary.frames
        ]
        for frame in dict.fromkeys(frames):
            other_root, chain = tf_root(frame, summary.tf_parents)
            if other_root != root:
                problems.append(
                    f"no tf joins '{frame}' to the global frame '{setup.global_frame}' (the bag's "
                    f"tf goes {' <- '.join(reversed(chain))} and {setup.global_frame} reaches "
                    f"{root})"
                )
    problems += [f"the clock jumps back: {j}" for j in summary.clock_jumps[:3]]
    return problems


# ------------------------------------------------------------------- outputs
def occupancy_to_pgm(grid: np.ndarray) -> np.ndarray:
    """map_saver's grey levels for OccupancyGrid values (row 0 = the map's bottom row)."""
    pgm = np.full(grid.shape, PGM_UNKNOWN, dtype=np.uint8)
    known = grid >= 0
    pgm[known & (grid <= FREE_MAX)] = PGM_FREE
    pgm[known & (grid >= OCCUPIED_MIN)] = PGM_OCCUPIED
    return np.flipud(pgm)  # images start at the top row


def write_map(
    grid: np.ndarray, resolution: float, origin: tuple[float, float], stem: Path
) -> tuple[Path, Path]:
    """A map_server map: ``stem.pgm`` (binary P5) and ``stem.yaml``."""
    pgm = occupancy_to_pgm(grid)
    height, width = pgm.shape
    pgm_path, yaml_path = stem.with_suffix(".pgm"), stem.with_suffix(".yaml")
    pgm_path.write_bytes(
        f"P5\n# downstream_perception replay\n{width} {height}\n255\n".encode() + pgm.tobytes()
    )
    meta = {
        "image": pgm_path.name,
        "resolution": float(resolution),
        "origin": [float(origin[0]), float(origin[1]), 0.0],
        "negate": 0,
        "occupied_thresh": OCCUPIED_MIN / 100.0,
        "free_thresh": 0.196,
    }
    yaml_path.write_text(yaml.safe_dump(meta, sort_keys=False))
    return pgm_path, yaml_path


def read_pgm(path: Path) -> np.ndarray:
    """A binary PGM (P5, 8 bit) as rows from the top."""
    data = path.read_bytes()
    tokens: list[bytes] = []
    pos = 0
    while len(tokens) < 4:
        while data[pos : pos + 1].isspace():
            pos += 1
        if data[pos : pos + 1] == b"#":
            pos = data.index(b"\n", pos) + 1
            continue
        end = pos
        while not data[end : end + 1].isspace():
            end += 1
        tokens.append(data[pos:end])
        pos = end
    if tokens[0] != b"P5" or int(tokens[3]) != 255:
        raise ValueError(f"{path}: not an 8-bit binary PGM")
    width, height = int(tokens[1]), int(tokens[2])
    pixels = np.frombuffer(data[pos + 1 : pos + 1 + width * height], dtype=np.uint8)
    return pixels.reshape(height, width)


def render_png(
    grid: np.ndarray, resolution: float, origin: tuple[float, float], path_xy: np.ndarray, out: Path
) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    height, width = grid.shape
    extent = (origin[0], origin[0] + width * resolution, origin[1], origin[1] + height * resolution)
    shown = np.where(grid < 0, np.nan, grid.astype(float))
    fig, ax = plt.subplots(figsize=(8, 8 * height / max(width, 1) + 0.5))
    cmap = matplotlib.colormaps["gray_r"].copy()
    cmap.set_bad("#7fb2b2")
    ax.imshow(
        shown, origin="lower", extent=extent, cmap=cmap, vmin=0, vmax=100, interpolation="nearest"
    )
    if len(path_xy):
        ax.plot(path_xy[:, 0], path_xy[:, 1], "-", color="#d62728", lw=1.5, label="robot path")
        ax.plot(*path_xy[0], "o", color="#2ca02c", label="start")
        ax.legend(loc="upper right")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("final costmap (black lethal, white free, teal unknown)")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def render_histograms(ages: dict[str, list[float]], out: Path) -> Path | None:
    if not any(ages.values()):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 3.5))
    for topic, values in ages.items():
        ax.hist(np.asarray(values) * 1e3, bins=40, alpha=0.6, label=topic)
    ax.set_xlabel("message stamp - newest /tf stamp recorded before it (ms)")
    ax.set_ylabel("messages")
    ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


# ------------------------------------------------------------------- progress
class Progress:
    """One line on stderr: done fraction, simulated time, ETA, messages per topic."""

    def __init__(self, total_s: float, stream: Any = sys.stderr, every_s: float = 0.5) -> None:
        self.total_s, self.stream, self.every_s = max(total_s, 1e-9), stream, every_s
        self.counts: Counter[str] = Counter()
        self.started = time.monotonic()
        self.shown = 0.0

    def line(self, done_s: float, now: float) -> str:
        fraction = min(1.0, max(0.0, done_s / self.total_s))
        elapsed = now - self.started
        eta = elapsed * (1.0 - fraction) / fraction if fraction > 0 else math.inf
        bar = "#" * int(30 * fraction)
        per_topic = " ".join(f"{t}:{n}" for t, n in sorted(self.counts.items()))
        eta_text = f"{eta:5.0f} s" if math.isfinite(eta) else "    ? s"
        done = f"{100 * fraction:5.1f}% {done_s:7.1f}/{self.total_s:.1f} s"
        return f"\r[{bar:<30}] {done}  ETA {eta_text}  {per_topic}"

    def line_end(self) -> None:
        self.stream.write(self.line(self.total_s, time.monotonic()) + "\n")
        self.stream.flush()

    def update(self, topic: str, done_s: float, force: bool = False) -> None:
        self.counts[topic] += 1
        now = time.monotonic()
        if force or now - self.shown >= self.every_s:
            self.shown = now
            self.stream.write(self.line(done_s, now))
            self.stream.flush()


# ------------------------------------------------------------------- the replay itself
@dataclass
class ReplayResult:
    grid: np.ndarray
    resolution: float
    origin: tuple[float, float]
    wall_s: float
    messages: Counter[str]
    diagnostics: dict[str, str]
    path_xy: np.ndarray


def robot_path(
    bag: Any, setup: CostmapSetup, summary: BagSummary, samples: int = 400
) -> np.ndarray:
    """global_frame <- robot_frame at evenly spaced times, from the bag's own tf."""
    import rospy
    import tf2_ros

    buffer = tf2_ros.Buffer(cache_time=rospy.Duration(summary.duration_s + 60.0), debug=False)
    with warnings.catch_warnings():
        # The bag's messages are of the classes stored in it, not the installed ones; tf2_ros warns
        # about every transform although the fields are the same.
        warnings.simplefilter("ignore", UserWarning)
        tf_topics = [t for t in TF_TOPICS if t in summary.topics]
        for topic, msg, _t in bag.read_messages(topics=tf_topics):
            for tf in msg.transforms:
                if topic == "/tf_static":
                    buffer.set_transform_static(tf, "bag")
                else:
                    buffer.set_transform(tf, "bag")
    points = []
    for t in np.linspace(summary.start_s, summary.end_s, samples):
        try:
            tf = buffer.lookup_transform(
                setup.global_frame, setup.robot_frame, rospy.Time.from_sec(t)
            )
        except tf2_ros.TransformException:
            continue
        points.append((tf.transform.translation.x, tf.transform.translation.y))
    return np.array(points).reshape(-1, 2)


@dataclass
class ReplayOptions:
    rate: float = 4.0  # times real time; 0: as fast as the messages can be published
    settle_s: float = 2.0  # simulated seconds after the last message (tf filter, update timers)
    timeout_s: float = 60.0  # for the nodelet to subscribe, and for the last costmap
    quiet: bool = False  # no progress bar


def replay(
    bag_path: Path, config_path: Path, options: ReplayOptions
) -> tuple[BagSummary, CostmapSetup, ReplayResult]:
    """Checks the bag against the configuration, then runs the costmap nodelet on it."""
    from downstream_perception.ros.processes import free_port, stop_process

    try:
        config = yaml.safe_load(config_path.read_text())
    except (OSError, yaml.YAMLError) as e:
        raise ReplayError(f"{config_path}: cannot read the configuration: {e}") from e
    setup = costmap_setup(config)
    bag = open_bag(bag_path)
    try:
        summary = summarize(bag, bag_path, [i.topic for i in setup.inputs])
        problems = check(summary, setup)
        if problems:
            raise ReplayError("; ".join(problems))
        path_xy = robot_path(bag, setup, summary)
        port = free_port()
        os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
        with open(os.devnull, "w") as log:
            procs = [subprocess.Popen(["roscore", "-p", str(port)], stdout=log, stderr=log)]
            try:
                run = NodeletRun(bag, summary, setup, options)
                run.start(config_path, port, procs, log)
                result = run.play()
                result.path_xy = path_xy
                return summary, setup, result
            finally:
                for proc in reversed(procs):
                    stop_process(proc)
    finally:
        bag.close()


class NodeletRun:
    """The costmap nodelet on a private master, fed the bag on simulated time."""

    def __init__(self, bag: Any, summary: BagSummary, setup: CostmapSetup, options: ReplayOptions):
        self.bag, self.summary, self.setup, self.options = bag, summary, setup, options
        self.topics = [i.topic for i in setup.inputs if i.topic in summary.topics]
        self.topics += [t for t in TF_TOPICS if t in summary.topics]
        self.diagnostics: dict[str, str] = {}

    def start(self, config_path: Path, port: int, procs: list[Any], log: Any) -> None:
        import rosgraph
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray
        from rosgraph_msgs.msg import Clock

        from downstream_perception.ros.costmap_client import CostmapClient

        deadline = time.monotonic() + 30.0
        while not rosgraph.is_master_online():
            if time.monotonic() > deadline:
                raise ReplayError("the private ROS master did not start")
            time.sleep(0.2)
        rospy.set_param("/use_sim_time", True)
        launch = [
            "roslaunch", "-p", str(port), PACKAGE, "costmap.launch",
            f"config:={config_path.resolve()}", "bond:=false",
        ]  # fmt: skip
        procs.append(subprocess.Popen(launch, stdout=log, stderr=log))
        self.launch = procs[-1]
        rospy.init_node("replay", anonymous=True, disable_signals=True)
        self.clock = rospy.Publisher("/clock", Clock, queue_size=10)
        self.clock.publish(Clock(rospy.Time.from_sec(self.summary.start_s)))
        rospy.Subscriber("/diagnostics", DiagnosticArray, self._on_diagnostics, queue_size=10)
        self.costmap = CostmapClient("/costmap/costmap")
        self.publishers = self._subscribed_publishers()

    def _on_diagnostics(self, msg: Any) -> None:
        for status in msg.status:
            if "costmap" in status.name:
                self.diagnostics.update({f"{status.name}: {v.key}": v.value for v in status.values})

    def _subscribed_publishers(self) -> dict[str, Any]:
        """A publisher per topic, of the bag's message class, once the nodelet subscribes."""
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
                    raise ReplayError(f"the costmap nodelet never subscribed to {topic}")
                time.sleep(0.1)
        return publishers

    def _publish_clock(self, t_s: float) -> None:
        import rospy
        from rosgraph_msgs.msg import Clock

        self.clock.publish(Clock(rospy.Time.from_sec(t_s)))

    def play(self) -> ReplayResult:
        rate, s = self.options.rate, self.summary
        stream = open(os.devnull, "w") if self.options.quiet else sys.stderr  # noqa: SIM115
        progress = Progress(s.duration_s, stream=stream)
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
        # Let the last messages through the tf filter and the update and publish timers run.
        steps = max(1, int(self.options.settle_s / 0.05))
        for k in range(1, steps + 1):
            self._publish_clock(s.end_s + k * 0.05)
            time.sleep(0.05 / max(rate, 1.0))
        wall_s = time.monotonic() - wall0
        progress.line_end()
        grid, resolution, origin = self._final_costmap()
        return ReplayResult(
            grid,
            resolution,
            origin,
            wall_s,
            progress.counts,
            dict(self.diagnostics),
            np.zeros((0, 2)),
        )

    def _final_costmap(self) -> tuple[np.ndarray, float, tuple[float, float]]:
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
        time.sleep(1.0)  # one more diagnostics round
        info = self.costmap.message().info
        return self.costmap.grid(), float(info.resolution), self.costmap.origin()


# ------------------------------------------------------------------- the report
def _image_html(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode()
    return f'<img alt="{html.escape(path.name)}" src="data:image/png;base64,{data}">'


def write_report(
    out: Path,
    summary: BagSummary,
    setup: CostmapSetup,
    result: ReplayResult,
    files: dict[str, Path],
) -> tuple[Path, Path]:
    grid = result.grid
    counts = {
        "lethal (>= 65)": int((grid >= OCCUPIED_MIN).sum()),
        "free (<= 25)": int(((grid >= 0) & (grid <= FREE_MAX)).sum()),
        "unknown": int((grid < 0).sum()),
    }
    messages = sum(n for _, n in summary.topics.values())
    speed = summary.duration_s / result.wall_s if result.wall_s > 0 else math.inf
    rejected = {
        k: v for k, v in result.diagnostics.items() if "rejected" in k and v not in ("0", "")
    }
    timing = {
        k: v
        for k, v in result.diagnostics.items()
        if any(
            w in k for w in ("integration time", "transform age", "messages received", "integrated")
        )
    }
    lines = [
        f"# Replay of `{summary.path.name}`",
        "",
        f"- bag: {summary.duration_s:.1f} s of data, {messages} messages on "
        f"{len(summary.topics)} topics",
        f"- replayed in {result.wall_s:.1f} s of wall time: {speed:.1f}x real time",
        f"- costmap: {grid.shape[1]} x {grid.shape[0]} cells at {result.resolution:.3f} m, "
        f"origin ({result.origin[0]:.2f}, {result.origin[1]:.2f}) in `{setup.global_frame}`",
        "- cells: " + ", ".join(f"{k} {v}" for k, v in counts.items()),
        f"- robot path: {len(result.path_xy)} poses of `{setup.global_frame}` <- "
        f"`{setup.robot_frame}`",
        "",
        "| topic | type | messages in the bag | replayed |",
        "|---|---|---|---|",
    ]
    for topic, (kind, n) in sorted(summary.topics.items()):
        lines.append(f"| `{topic}` | {kind} | {n} | {result.messages.get(topic, 0)} |")
    lines += ["", "## Rejections (costmap diagnostics)", ""]
    lines += [f"- {k}: {v}" for k, v in sorted(rejected.items())] or ["- none"]
    lines += ["", "## Processing (costmap diagnostics: counts, and mean and max per source)", ""]
    lines += [f"- {k}: {v}" for k, v in sorted(timing.items())] or ["- no source reported"]
    lines += ["", "## Files", ""] + [f"- {k}: `{p.name}`" for k, p in files.items()]
    images = [("costmap", files.get("png")), ("transform ages", files.get("ages"))]
    md_lines = list(lines)
    for title, image in images:
        if image is not None:
            md_lines += ["", f"## {title.capitalize()}", "", f"![{title}]({image.name})"]
    md = out / "report.md"
    md.write_text("\n".join(md_lines) + "\n")
    body = "".join(f"<pre>{html.escape(chr(10).join(lines))}</pre>")
    for title, image in images:
        if image is not None:
            body += f"<h2>{html.escape(title.capitalize())}</h2>{_image_html(image)}"
    page = out / "report.html"
    page.write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>replay</title></head>"
        f"<body>{body}</body></html>\n"
    )
    return md, page


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("bag", type=Path)
    ap.add_argument("--config", type=Path, required=True, help="the costmap YAML (as on the robot)")
    ap.add_argument("--out", type=Path, default=Path("out/replay"))
    ap.add_argument(
        "--rate", type=float, default=4.0, help="times real time (0: as fast as possible)"
    )
    ap.add_argument(
        "--settle-s", type=float, default=2.0, help="simulated seconds after the last message"
    )
    ap.add_argument(
        "--timeout-s", type=float, default=60.0, help="for the nodelet to start and to publish"
    )
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    args = ap.parse_args(argv)
    if not (math.isfinite(args.rate) and args.rate >= 0):
        ap.error("--rate must be >= 0")
    options = ReplayOptions(args.rate, args.settle_s, args.timeout_s, args.quiet)
    try:
        summary, setup, result = replay(args.bag, args.config, options)
    except ReplayError as e:
        print(f"replay: {e}", file=sys.stderr)
        return 2
    args.out.mkdir(parents=True, exist_ok=True)
    files: dict[str, Path] = {}
    files["pgm"], files["yaml"] = write_map(
        result.grid, result.resolution, result.origin, args.out / "costmap"
    )
    files["png"] = render_png(
        result.grid, result.resolution, result.origin, result.path_xy, args.out / "costmap.png"
    )
    ages = render_histograms(summary.transform_ages_s, args.out / "transform_ages.png")
    if ages is not None:
        files["ages"] = ages
    md, page = write_report(args.out, summary, setup, result, files)
    print(
        f"replay: {summary.duration_s:.1f} s of bag in {result.wall_s:.1f} s; wrote {md} and {page}"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
