#!/usr/bin/env python3
"""Soaks (report, never assert): the live costmap and the TSDF nodelets, each alone in a nodelet
manager (--no-bond), fed for --minutes (default 10) on a private ROS master; the manager's RSS
(/proc/<pid>/status VmRSS) and the nodelet's diagnostics sampled every 5 s.

1. costmap (bench/soak_costmap.launch, bench/soak_costmap.yaml: 12 m rolling window, obstacle
   layer + inflation, update 10 Hz, publish 5 Hz): this process plays 720-beam scans of the
   warehouse aisle and tf, the robot driving up and down the aisle at 1 m/s (so the window
   rolls, the footprint clears and the crossing person is marked and cleared again). The scan
   rate starts at 10 Hz and doubles every 7 s during the first minute while each step is
   sustained (see judge_step); the highest sustained rate is then held to the end.
2. tsdf (bench/soak_tsdf.launch, bench/soak_tsdf.yaml: distance eviction at 3 m, OctoMap on):
   depth_sim_node.py walks an endless corridor at 1 m/s, 320x240 frames at 15 Hz.

Minute 0 is the first message the nodelet handled. Growth after the first minute = RSS at the
end over RSS at 1 minute. Writes out/soak.md (tables) and out/soak_<name>.csv (every sample),
prints a closing line. Usage: make soak [SOAK_MINUTES=10] [SOAK_ONLY=costmap|tsdf], or in a
sourced workspace: python3 bench/soak.py --minutes 1 --only tsdf
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

SAMPLE_PERIOD_S = 5.0
RAMP_START_HZ, RAMP_MAX_HZ, RAMP_STEP_S = 10.0, 2560.0, 6.0  # 10 .. 2560 Hz: 9 steps, 54 s
RAMP_SETTLE_S = 2.0  # each step is judged on its last RAMP_STEP_S - RAMP_SETTLE_S seconds
GROWTH_LIMIT_PCT = 5.0  # issue 17: "both soaks grow RSS by less than 5 % after the first minute"
NUM_BEAMS = 720
UPDATE_HZ = 10.0  # bench/soak_costmap.yaml update_frequency
TSDF_RATE_HZ = 15.0


# ------------------------------------------------------------------ bookkeeping (pure)
@dataclass
class Sample:
    t_s: float  # since the first message handled
    rss_kb: int
    handled: int  # messages the nodelet handled so far
    figures: dict[str, float] = field(default_factory=dict)  # diagnostics, by short name


@dataclass
class SoakResult:
    name: str
    what: str  # messages handled, e.g. "scans integrated"
    rate_hz: float
    samples: list[Sample]
    notes: list[str] = field(default_factory=list)
    ramp: list[dict[str, Any]] = field(default_factory=list)

    def at(self, t_s: float) -> Sample:
        return sample_at(self.samples, t_s)

    @property
    def growth_after_first_minute_pct(self) -> float:
        return growth_pct(self.at(60.0).rss_kb, self.samples[-1].rss_kb)


def sample_at(samples: Sequence[Sample], t_s: float) -> Sample:
    """The first sample taken at or after t_s (the last one if none is)."""
    if not samples:
        raise ValueError("no samples")
    return next((s for s in samples if s.t_s >= t_s), samples[-1])


def growth_pct(before_kb: float, after_kb: float) -> float:
    """RSS growth from `before` to `after` in % of `before` (NaN without a baseline)."""
    if not before_kb > 0:
        return math.nan
    return 100.0 * (after_kb - before_kb) / before_kb


def trend_mb_per_min(samples: Sequence[Sample], after_s: float = 60.0) -> float:
    """Least-squares slope of RSS (MB per minute) over the samples from after_s on: the growth
    that goes on, less sensitive than the end point to malloc's swings (NaN with < 2 samples)."""
    pts = [(s.t_s / 60.0, s.rss_kb / 1024.0) for s in samples if s.t_s >= after_s]
    if len(pts) < 2:
        return math.nan
    mt = sum(t for t, _ in pts) / len(pts)
    mr = sum(r for _, r in pts) / len(pts)
    var = sum((t - mt) ** 2 for t, _ in pts)
    if var == 0:
        return math.nan
    return sum((t - mt) * (r - mr) for t, r in pts) / var


def rate_between(a: Sample, b: Sample, figure: str | None = None) -> float:
    """Messages handled (or a figure that counts) per second from sample a to sample b."""
    if not b.t_s > a.t_s:
        return math.nan
    if figure is None:
        return (b.handled - a.handled) / (b.t_s - a.t_s)
    return (b.figures.get(figure, math.nan) - a.figures.get(figure, math.nan)) / (b.t_s - a.t_s)


def mb(kb: float) -> str:
    return f"{kb / 1024.0:.1f}"


@dataclass
class Counters:
    """The costmap's counters from one diagnostics message, with what this process had sent."""

    t_s: float  # wall time at receipt
    sent: int
    received: int
    integrated: int
    updates: int
    skipped: int  # updates skipped because the previous one still ran
    age_mean_s: float  # mean (over all scans so far) of scan stamp -> integration
    publish_age_s: list[float] = field(default_factory=list)  # costmap messages in this window


def step_figures(a: Counters, b: Counters) -> dict[str, float]:
    """What happened between two snapshots: rates (Hz) and latencies (ms, NaN if unmeasured)."""
    dt = b.t_s - a.t_s
    integrated = b.integrated - a.integrated
    latency = math.nan
    if integrated > 0:  # the diagnostics give a mean over all scans so far: this window's mean
        latency = 1e3 * (b.age_mean_s * b.integrated - a.age_mean_s * a.integrated) / integrated
    ages = sorted(b.publish_age_s)
    return {
        "dt_s": dt,
        "sent": float(b.sent - a.sent),
        "integrated": float(integrated),
        "received": float(b.received - a.received),
        "sent_hz": (b.sent - a.sent) / dt if dt > 0 else math.nan,
        "integrated_hz": integrated / dt if dt > 0 else math.nan,
        "update_hz": (b.updates - a.updates) / dt if dt > 0 else math.nan,
        "skipped": float(b.skipped - a.skipped),
        "scan_latency_ms": latency,
        "publish_latency_ms": 1e3 * ages[len(ages) // 2] if ages else math.nan,
    }


def judge_step(a: Counters, b: Counters, rate_hz: float, update_hz: float) -> str | None:
    """None if the costmap sustained rate_hz from a to b, else why not. Sustained: the feed kept
    >= 95 % of the rate (else the feed is the limit), >= 98 % of the scans sent were integrated
    (none dropped at the subscriber queue or waiting for tf), the update loop kept >= 90 % of its
    rate without skipping an update, a scan's mean stamp -> integration latency <= 50 ms and the
    costmap messages' median stamp -> receipt latency <= 50 ms (b.publish_age_s: the messages
    received between a and b)."""
    f = step_figures(a, b)
    if not f["dt_s"] > 0:
        return "no time between the snapshots"
    if f["sent_hz"] < 0.95 * rate_hz:
        return f"feed limit: sent {f['sent_hz']:.0f} Hz of {rate_hz:.0f}"
    slack = max(2.0, 0.02 * f["sent"])  # scans in flight at either snapshot
    if f["integrated"] < f["sent"] - slack:
        return (
            f"integrated {f['integrated']:.0f} of {f['sent']:.0f} scans "
            f"({f['received']:.0f} received)"
        )
    if f["skipped"] > 0:
        return f"{f['skipped']:.0f} updates skipped (previous still running)"
    if f["update_hz"] < 0.9 * update_hz - 1.0 / f["dt_s"]:
        return f"update loop at {f['update_hz']:.1f} Hz of {update_hz:.0f}"
    if f["scan_latency_ms"] > 50.0:
        return f"scan latency {f['scan_latency_ms']:.0f} ms (stamp -> integration)"
    if f["publish_latency_ms"] > 50.0:
        return f"publish latency {f['publish_latency_ms']:.0f} ms (median, stamp -> receipt)"
    return None


def markdown(results: Sequence[SoakResult], load: str) -> list[str]:
    lines = [
        "# Soaks (make soak)",
        "",
        f"Load average (1, 5, 15 min) {load}; 2 shared cores.",
        "",
        "| soak | rate (Hz) | minutes | messages handled | RSS start (MB) | RSS 1 min (MB) "
        "| RSS end (MB) | growth after 1 min | < 5 % | trend after 1 min (MB/min) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        start, minute, end = r.samples[0], r.at(60.0), r.samples[-1]
        g = r.growth_after_first_minute_pct
        lines.append(
            f"| {r.name} | {r.rate_hz:.0f} | {end.t_s / 60.0:.1f} | {end.handled:,} {r.what} "
            f"| {mb(start.rss_kb)} | {mb(minute.rss_kb)} | {mb(end.rss_kb)} | {g:+.2f} % "
            f"| {'yes' if g < GROWTH_LIMIT_PCT else 'NO'} | {trend_mb_per_min(r.samples):+.3f} |"
        )
    for r in results:
        keys = sorted({k for s in r.samples for k in s.figures})
        if keys:
            lines += ["", f"## {r.name}: diagnostics", "", "| figure | start | 1 min | end |"]
            lines.append("|---|---|---|---|")
            for k in keys:
                cells = [s.figures.get(k, math.nan) for s in (r.samples[0], r.at(60.0))]
                cells.append(r.samples[-1].figures.get(k, math.nan))
                lines.append(f"| {k} | " + " | ".join(f"{v:,.6g}" for v in cells) + " |")
        if r.ramp:
            lines += ["", f"## {r.name}: rate steps (first minute)", ""]
            lines += [
                "| scan rate (Hz) | sent (Hz) | integrated (Hz) | scan latency (ms) "
                "| costmap publish latency (ms) | sustained |",
                "|---|---|---|---|---|---|",
            ]
            for st in r.ramp:
                lines.append(
                    f"| {st['rate_hz']:.0f} | {st.get('sent_hz', math.nan):.0f} "
                    f"| {st.get('integrated_hz', math.nan):.0f} "
                    f"| {st.get('scan_latency_ms', math.nan):.1f} "
                    f"| {st.get('publish_latency_ms', math.nan):.1f} | {st['verdict'] or 'yes'} |"
                )
        lines += [""] + [f"- {n}" for n in r.notes]
    return lines + [""]


def closing_line(results: Sequence[SoakResult]) -> str:
    parts = []
    for r in results:
        g = r.growth_after_first_minute_pct
        parts.append(
            f"{r.name} {r.samples[-1].handled:,} {r.what} at {r.rate_hz:.0f} Hz, RSS "
            f"{mb(r.samples[0].rss_kb)} -> {mb(r.at(60.0).rss_kb)} -> "
            f"{mb(r.samples[-1].rss_kb)} MB ({g:+.2f} % after 1 min)"
        )
    ok = all(r.growth_after_first_minute_pct < GROWTH_LIMIT_PCT for r in results)
    verdict = "all" if ok else "NOT all"
    return f"soak: {'; '.join(parts)}; {verdict} under {GROWTH_LIMIT_PCT:.0f} %"


def write_csv(path: Path, r: SoakResult) -> None:
    keys = sorted({k for s in r.samples for k in s.figures})
    with path.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s", "rss_kb", "handled", *keys])
        for s in r.samples:
            w.writerow([f"{s.t_s:.1f}", s.rss_kb, s.handled, *(s.figures.get(k, "") for k in keys)])


def number(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return math.nan


# ------------------------------------------------------------------ processes and ROS
def rss_kb(pid: int) -> int:
    for line in Path(f"/proc/{pid}/status").read_text().splitlines():
        if line.startswith("VmRSS:"):
            return int(line.split()[1])
    raise RuntimeError(f"no VmRSS for pid {pid}")


def smaps_breakdown(smaps: str) -> dict[str, float]:
    """RSS by kind of mapping (MB) from /proc/<pid>/smaps: the main heap; glibc's other malloc
    arenas (one per thread that allocates: anonymous mappings at 64 MiB-aligned addresses); other
    anonymous mappings (big allocations, the TSDF's 2 MiB chunks, stacks of threads); files
    (libraries); how much of all anonymous memory sits in transparent huge pages."""
    kb = {"heap": 0, "malloc arenas": 0, "anonymous": 0, "huge pages": 0, "files": 0, "other": 0}
    kind = "other"
    for line in smaps.splitlines():
        fields = line.split()
        if not fields:
            continue
        if "-" in fields[0] and not fields[0].endswith(":"):  # a mapping's header line
            path = fields[5] if len(fields) > 5 else ""
            start = int(fields[0].split("-")[0], 16)
            if path == "[heap]":
                kind = "heap"
            elif not path:
                kind = "malloc arenas" if start % (64 << 20) == 0 else "anonymous"
            else:
                kind = "files" if path.startswith("/") else "other"
        elif fields[0] == "Rss:":
            kb[kind] += int(fields[1])
        elif fields[0] == "AnonHugePages:":
            kb["huge pages"] += int(fields[1])
    return {f"RSS {k} (MB)": v / 1024.0 for k, v in kb.items()}


def rss_figures(pid: int) -> dict[str, float]:
    try:
        return smaps_breakdown(Path(f"/proc/{pid}/smaps").read_text())
    except OSError:
        return {}


class Processes:
    """What this script started, each in a session of its own (so a Ctrl-C reaches this script
    only, and stop() ends each group: roslaunch and its nodes)."""

    def __init__(self) -> None:
        self.procs: list[subprocess.Popen[bytes]] = []

    def start(self, args: list[str], log: Path) -> subprocess.Popen[bytes]:
        with log.open("ab") as out:
            proc = subprocess.Popen(
                args, stdout=out, stderr=subprocess.STDOUT, start_new_session=True
            )
        self.procs.append(proc)
        return proc

    @staticmethod
    def stop(proc: subprocess.Popen[bytes]) -> None:
        for sig, wait_s in ((signal.SIGINT, 20.0), (signal.SIGTERM, 5.0), (signal.SIGKILL, 5.0)):
            try:
                os.killpg(proc.pid, sig)  # the group is the one this script started
            except ProcessLookupError:
                break
            try:
                proc.wait(timeout=wait_s)
                # roslaunch is gone; anything left in its group (a node that ignored it) goes too.
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                break
            except subprocess.TimeoutExpired:
                continue
            break

    def stop_all(self) -> None:
        while self.procs:
            self.stop(self.procs.pop())


class Diagnostics:
    """The latest values of every /diagnostics status, by status name."""

    def __init__(self, on_status: Callable[[str, dict[str, str]], None] | None = None) -> None:
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray

        self.lock = threading.Lock()
        self.latest: dict[str, dict[str, str]] = {}
        self.on_status = on_status
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_array, queue_size=50)

    def on_array(self, msg: Any) -> None:
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            values["_message"] = status.message
            with self.lock:
                self.latest[status.name] = values
            if self.on_status:
                self.on_status(status.name, values)

    def get(self, suffix: str) -> dict[str, str]:
        with self.lock:
            return next((v for k, v in self.latest.items() if k.endswith(suffix)), {})


def final_status(diagnostics: Diagnostics, suffixes: Sequence[str]) -> list[str]:
    """The last diagnostics summaries (a WARN that stays, e.g. messages stuck waiting for tf)."""
    notes = []
    for suffix in suffixes:
        v = diagnostics.get(suffix)
        waits = {k: x for k, x in v.items() if "waiting for tf" in k}
        detail = f"; {waits}" if waits else ""
        notes.append(f"last diagnostics '{suffix[2:]}': {v.get('_message', '(none)')}{detail}")
    return notes


def node_pid(name: str, timeout_s: float = 60.0) -> int:
    """The pid of a node on our master (its XML-RPC getPid)."""
    import xmlrpc.client

    import rosgraph

    master = rosgraph.Master("/soak")
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        try:
            uri = master.lookupNode(name)
            code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/soak")
            if code == 1:
                return int(pid)
        except Exception:  # not registered yet
            pass
        time.sleep(0.5)
    raise RuntimeError(f"node {name} did not come up in {timeout_s:.0f} s")


def wait_for(predicate: Callable[[], bool], timeout_s: float, what: str) -> None:
    deadline = time.time() + timeout_s
    while not predicate():
        if time.time() > deadline:
            raise RuntimeError(f"soak: {what} within {timeout_s:.0f} s")
        time.sleep(0.2)


def sample_loop(
    pid: int,
    minutes: float,
    handled: Callable[[], int],
    figures: Callable[[], dict[str, float]],
    every_step: Callable[[float], None] | None = None,
) -> tuple[list[Sample], list[str]]:
    """From the first message handled: a sample every SAMPLE_PERIOD_S until `minutes` are over
    or the manager dies. every_step(t) runs every 0.2 s (the costmap's rate ramp)."""
    notes: list[str] = []
    wait_for(lambda: handled() > 0, 180.0, "no message handled")
    t0 = time.time()
    samples: list[Sample] = []
    next_sample = 0.0
    while True:
        t = time.time() - t0
        if t >= next_sample or t >= 60.0 * minutes:
            try:
                f = figures()
                f.update(rss_figures(pid))
                samples.append(Sample(t, rss_kb(pid), handled(), f))
            except (FileNotFoundError, ProcessLookupError):
                notes.append(f"the manager (pid {pid}) died at {t:.0f} s")
                break
            next_sample += SAMPLE_PERIOD_S
            if t >= 60.0 * minutes:
                break
        if every_step:
            every_step(t)
        time.sleep(0.2)
    return samples, notes


def pick(values: dict[str, str], keys: dict[str, str]) -> dict[str, float]:
    return {short: number(values[key]) for short, key in keys.items() if key in values}


# ------------------------------------------------------------------ costmap soak
class ScanFeed:
    """Scans of the warehouse aisle and odom -> base_link tf at a rate that can change, the robot
    driving up and down the aisle at 1 m/s."""

    def __init__(self) -> None:
        import numpy as np
        import rospy
        import tf2_ros
        from sensor_msgs.msg import LaserScan

        from downstream_perception.planar import se2_matrix
        from downstream_perception.sim import Lidar, LidarConfig, Trajectory, warehouse_aisle

        self.rospy = rospy
        self.np = np
        self.se2 = se2_matrix
        self.world = warehouse_aisle()
        self.lidar = Lidar(LidarConfig(num_beams=NUM_BEAMS, range_max=30.0, noise_std_m=0.01))
        self.drive = Trajectory(np.array([[0.0, 1.0, 0.0], [17.0, 18.0, 0.0], [34.0, 1.0, 0.0]]))
        self.map_odom = se2_matrix(0.5, -0.2, 0.05)  # a localizer's correction, as sim_node
        self.odom_map = np.linalg.inv(self.map_odom)
        self.pub = rospy.Publisher("/soak/scan", LaserScan, queue_size=50)
        self.tf = tf2_ros.TransformBroadcaster()
        self.rate_hz = RAMP_START_HZ
        self.sent = 0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.static: Any = None

    def static_tf(self) -> Any:
        import tf2_ros

        from downstream_perception.ros.util import transform_stamped

        b = tf2_ros.StaticTransformBroadcaster()
        now = self.rospy.Time.now()
        m = self.map_odom
        b.sendTransform(
            [
                transform_stamped("map", "odom", now, m[0, 2], m[1, 2], 0.0, 0.05),
                transform_stamped("base_link", "laser", now, z=0.2),
            ]
        )
        return b

    def run(self) -> None:
        from downstream_perception.ros.util import laser_scan, transform_stamped

        c = self.lidar.config
        t0 = time.time()
        deadline = time.time()
        while not self.stop.is_set() and not self.rospy.is_shutdown():
            stamp = self.rospy.Time.now()
            t = (time.time() - t0) % self.drive.duration
            x, y, yaw = self.drive.pose(t)
            odom_base = self.odom_map @ self.se2(x, y, yaw)
            oyaw = math.atan2(odom_base[1, 0], odom_base[0, 0])
            self.tf.sendTransform(
                transform_stamped(
                    "odom", "base_link", stamp, odom_base[0, 2], odom_base[1, 2], 0, oyaw
                )
            )
            ranges = self.lidar.scan(self.world, (x, y, yaw), t)
            msg = laser_scan(
                stamp, "laser", ranges, c.angle_min, c.angle_increment, c.range_min, c.range_max
            )
            msg.scan_time = 1.0 / self.rate_hz
            self.pub.publish(msg)
            self.sent += 1
            deadline += 1.0 / self.rate_hz
            behind = time.time() - deadline
            if behind > 0.1:  # late by more than 0.1 s: no burst to catch up, just carry on
                deadline = time.time()
            elif behind < 0:
                time.sleep(-behind)


def costmap_soak(procs: Processes, port: int, out: Path, minutes: float) -> SoakResult:
    import rospy
    from map_msgs.msg import OccupancyGridUpdate
    from nav_msgs.msg import OccupancyGrid

    feed = ScanFeed()
    publish_ages: list[float] = []
    ages_lock = threading.Lock()

    def on_update(msg: Any) -> None:
        with ages_lock:
            publish_ages.append((rospy.Time.now() - msg.header.stamp).to_sec())

    # A rolling window publishes full grids (the origin moves); both kinds carry the publish time.
    subscribers = [
        rospy.Subscriber("/costmap/costmap", OccupancyGrid, on_update, queue_size=5),
        rospy.Subscriber("/costmap/costmap_updates", OccupancyGridUpdate, on_update, queue_size=20),
    ]
    snapshots: list[Counters] = []
    snap_lock = threading.Lock()

    def on_status(name: str, v: dict[str, str]) -> None:
        if not name.endswith(": layer obstacles"):
            return
        cm = diagnostics.get(": costmap")
        with ages_lock:
            ages = publish_ages[:]
            publish_ages.clear()
        c = Counters(
            time.time(),
            feed.sent,
            int(number(v.get("scan: messages received", "0"))),
            int(number(v.get("scan: messages integrated", "0"))),
            int(number(cm.get("updates", "0"))),
            int(number(cm.get("updates skipped (previous still running)", "0"))),
            number(v.get("scan: transform age at integration mean (s)", "0")),
            ages,
        )
        with snap_lock:
            snapshots.append(c)

    diagnostics = Diagnostics(on_status)
    feed.static = feed.static_tf()  # held: it publishes while it lives
    procs.start(
        ["roslaunch", "-p", str(port), "downstream_perception", "soak_costmap.launch"],
        out / "soak_costmap.log",
    )
    pid = node_pid("/soak_manager")
    wait_for(lambda: feed.pub.get_num_connections() > 0, 60.0, "the costmap did not subscribe")
    feed.thread.start()
    ramp: list[dict[str, Any]] = []
    step_start = [0.0]
    holding = [False]

    def step(t: float) -> None:
        """The ramp: judge the step that ends now; go up, or back to the last sustained rate."""
        if holding[0] or t - step_start[0] < RAMP_STEP_S:
            return
        with snap_lock:
            window = [s for s in snapshots if s.t_s - t0[0] >= step_start[0] + RAMP_SETTLE_S]
        verdict: str | None = "no diagnostics in the step"
        record: dict[str, Any] = {"rate_hz": feed.rate_hz}
        if len(window) >= 2:
            merged = Counters(**{**window[-1].__dict__, "publish_age_s": []})
            merged.publish_age_s = [a for s in window[1:] for a in s.publish_age_s]
            verdict = judge_step(window[0], merged, feed.rate_hz, UPDATE_HZ)
            record.update(step_figures(window[0], merged))
        record["verdict"] = verdict
        ramp.append(record)
        if verdict is not None:
            feed.rate_hz = max(RAMP_START_HZ, feed.rate_hz / 2.0)
            holding[0] = True
        elif feed.rate_hz * 2.0 > RAMP_MAX_HZ or t + RAMP_STEP_S > 60.0:
            holding[0] = True
        else:
            feed.rate_hz *= 2.0
        step_start[0] = t

    t0 = [time.time()]

    def handled() -> int:
        n = int(number(diagnostics.get(": layer obstacles").get("scan: messages integrated", "0")))
        if n == 0:
            t0[0] = time.time()  # the sample loop's minute 0 is the first scan integrated
        return n

    keys_layer = {
        "scans received": "scan: messages received",
        "scans rejected": "scan: messages rejected",
        "obstacle layer memory (bytes)": "memory (bytes)",
        "cells occupied": "cells occupied",
        "scan integration mean (ms)": "scan: integration time mean (ms)",
    }
    keys_costmap = {
        "updates": "updates",
        "update time mean (ms)": "update time mean (ms)",
        "updates skipped": "updates skipped (previous still running)",
        "full grids published": "full grids published",
        "updates published": "updates published",
    }

    def figures() -> dict[str, float]:
        f = pick(diagnostics.get(": layer obstacles"), keys_layer)
        f.update(pick(diagnostics.get(": costmap"), keys_costmap))
        f["scans sent"] = float(feed.sent)
        return f

    try:
        samples, notes = sample_loop(pid, minutes, handled, figures, step)
    finally:
        feed.stop.set()
        feed.thread.join(timeout=5.0)
        procs.stop_all()
        for sub in subscribers:
            sub.unregister()
        diagnostics.sub.unregister()
        feed.pub.unregister()
    notes += final_status(diagnostics, (": costmap", ": layer obstacles"))
    held = feed.rate_hz
    notes.insert(0, f"scan rate held after the ramp: {held:.0f} Hz ({NUM_BEAMS} beams)")
    if holding[0] and samples and samples[-1].t_s > step_start[0]:
        a, b = sample_at(samples, step_start[0]), samples[-1]
        sent, integrated = rate_between(a, b, "scans sent"), rate_between(a, b)
        notes.insert(
            1,
            f"over the hold ({a.t_s:.0f} .. {b.t_s:.0f} s): {sent:.0f} Hz sent, "
            f"{integrated:.0f} Hz integrated",
        )
    return SoakResult("costmap", "scans integrated", held, samples, notes, ramp)


# ------------------------------------------------------------------ TSDF soak
def tsdf_soak(procs: Processes, port: int, out: Path, minutes: float) -> SoakResult:
    diagnostics = Diagnostics()
    frames = int(TSDF_RATE_HZ * 60.0 * (minutes + 1.0))  # the soak ends before the walk does
    procs.start(
        [
            "roslaunch",
            "-p",
            str(port),
            "downstream_perception",
            "soak_tsdf.launch",
            f"frames:={frames}",
        ],
        out / "soak_tsdf.log",
    )
    pid = node_pid("/soak_manager")
    keys = {
        "frames rejected": "frames rejected",
        "blocks": "blocks",
        "TSDF memory (MB)": "memory (MB)",
        "blocks evicted by distance": "blocks evicted by distance (total)",
        "integration mean (ms)": "integration time mean (ms)",
        "mesh triangles": "mesh triangles",
        "OctoMap observations inserted": "octomap: observations inserted",
        "OctoMap observations dropped": "octomap: observations dropped (queue full: insertion "
        "slower than the sensor)",
        "OctoMap leaves": "octomap: leaves",
        "OctoMap nodes": "octomap: nodes",
        "OctoMap memory (MB)": "octomap: memory (MB)",
        "OctoMap nodes evicted by distance": "octomap: nodes evicted by distance (total)",
        "OctoMap nodes evicted at the cap": "octomap: nodes evicted at the memory cap (total)",
    }

    def handled() -> int:
        return int(number(diagnostics.get(": tsdf").get("frames integrated", "0")))

    try:
        samples, notes = sample_loop(
            pid, minutes, handled, lambda: pick(diagnostics.get(": tsdf"), keys)
        )
    finally:
        procs.stop_all()
        diagnostics.sub.unregister()
    notes += final_status(diagnostics, (": tsdf",))
    notes.insert(0, "depth frames 320x240 at 15 Hz, the camera walking a corridor at 1 m/s")
    return SoakResult("tsdf", "frames integrated", TSDF_RATE_HZ, samples, notes)


# ------------------------------------------------------------------ main
def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--minutes", type=float, default=10.0, help="length of each soak")
    ap.add_argument("--only", choices=("costmap", "tsdf"), help="run one soak only")
    ap.add_argument("--out", type=Path, default=Path("out"))
    args = ap.parse_args(argv)
    if not args.minutes > 0:
        ap.error("--minutes must be positive")
    args.out.mkdir(parents=True, exist_ok=True)
    from downstream_perception.ros.processes import free_port

    port = free_port()
    os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
    # SIGTERM (a CI timeout, kill) cleans up as Ctrl-C does; SIGINT too when a shell started us
    # in the background (which ignores it: Python then installs no handler of its own).
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGTERM, lambda *_: (_ for _ in ()).throw(KeyboardInterrupt()))
    procs = Processes()
    results: list[SoakResult] = []
    load_start = load_average()
    try:
        procs.start(["roscore", "-p", str(port)], args.out / "soak_roscore.log")
        master = Processes()  # roscore outlives the soaks' launches
        master.procs, procs.procs = procs.procs, []
        try:
            import rospy

            wait_for(master_up, 30.0, "roscore did not come up")
            rospy.init_node("soak", disable_signals=True)
            for name, soak in (("costmap", costmap_soak), ("tsdf", tsdf_soak)):
                if args.only in (None, name):
                    print(f"soak: {name} for {args.minutes:g} min ...", flush=True)
                    r = soak(procs, port, args.out, args.minutes)
                    write_csv(args.out / f"soak_{name}.csv", r)
                    results.append(r)
            rospy.signal_shutdown("soak done")
        finally:
            procs.stop_all()
            master.stop_all()
    except KeyboardInterrupt:
        print("soak: interrupted; processes stopped", file=sys.stderr)
        return 130
    load = f"{load_start} at the start, {load_average()} at the end"
    (args.out / "soak.md").write_text("\n".join(markdown(results, load)))
    print("\n".join(markdown(results, load)))
    print(closing_line(results))
    return 0


def load_average() -> str:
    return ", ".join(f"{v:.2f}" for v in os.getloadavg())


def master_up() -> bool:
    import rosgraph

    return bool(rosgraph.is_master_online())


if __name__ == "__main__":
    sys.exit(main())
