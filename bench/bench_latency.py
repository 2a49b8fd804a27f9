"""End-to-end latency benchmark (report, never assert): from a scan's stamp to the first
published costmap that contains it, and from a detection's stamp to the first published costmap
whose tracked-obstacle cells show it, with the real tracker and costmap nodelets
(bench/bench_latency.launch, bench/bench_latency.yaml: update and publish at 10 Hz).

One process plays the sensors on its own ROS master: scans at 10 Hz, each with a small blip at
one of 8 places (one return marks a cell LETHAL, the next two scans' pass-throughs clear it), and
detections at 15 Hz of short-lived objects (a new one every 0.5 s, seen for 0.4 s, each at its
own place; the obstacle layer marks on one return from a floor of -0.5, as costmap_2d
marks). Latency = the receive time of the first costmap message (full grid or update) in
which the blip's or object's cell is LETHAL, minus the message's stamp (a message received
before the probe handled the scan itself counts too: each subscription has its own thread);
for objects both from the first detection (what a planner experiences, including the
tracker's min_hits confirmation) and from the confirming detection. The receive times are
taken by a probe in a process of its own (this file run with --probe), which learns what to
watch from the scans and detections it receives: in the sensors' process the probe's callbacks
waited for the interpreter lock while the sensor loops ran, which added up to tens of
milliseconds to some latencies.

Used by bench.py; runnable alone in a sourced workspace: python3 bench/bench_latency.py
"""

from __future__ import annotations

import collections
import json
import multiprocessing
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from typing import Any

import numpy as np

RES, ORIGIN = 0.05, (-3.0, -5.0)
BLIP_Y, BLIPS = 2.02, [1.0 + 0.9 * k for k in range(8)]  # scan blips: 12 cm posts (m, map)
OBJECT_Y, OBJECT_SLOTS = -1.975, [1.025 + 1.0 * k for k in range(10)]
SCAN_HZ, DETECTION_HZ = 10.0, 15.0
OBJECT_PERIOD_S, OBJECT_LIFE_S = 0.5, 0.4


def cell(x: float, y: float) -> tuple[int, int]:
    return int(np.floor((y - ORIGIN[1]) / RES)), int(np.floor((x - ORIGIN[0]) / RES))


class Probe:
    """Follows the costmap (full grids + updates) and timestamps when watched cells turn lethal."""

    def __init__(self) -> None:
        import rospy
        from map_msgs.msg import OccupancyGridUpdate
        from nav_msgs.msg import OccupancyGrid

        self.rospy = rospy
        self.lock = threading.Lock()
        self.grid: np.ndarray | None = None
        # key -> (stamps to measure from, window rows/cols); measured keys move to results.
        self.pending: dict[Any, tuple[list[Any], tuple[slice, slice]]] = {}
        self.results: dict[str, list[list[float]]] = {"scan": [], "object": []}
        # The costmap messages of the last few seconds (receive time, row, column, cells): the
        # costmap can answer a scan before this process has handled that scan itself (each
        # subscription has its own thread), so a new watch first looks back through them.
        self.recent: collections.deque[tuple[Any, int, int, np.ndarray]] = collections.deque(
            maxlen=100
        )
        self.missed = {"scan": 0, "object": 0}
        rospy.Subscriber(
            "/costmap/costmap", OccupancyGrid, self.on_full, queue_size=5, tcp_nodelay=True
        )
        rospy.Subscriber(
            "/costmap/costmap_updates",
            OccupancyGridUpdate,
            self.on_update,
            queue_size=50,
            tcp_nodelay=True,
        )
        from diagnostic_msgs.msg import DiagnosticArray

        # The costmap's own figure: data stamp -> costmap message handed to the publisher (the
        # last 200 publishes), free of this process's receive path.
        self.host: dict[str, float] = {}
        rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=20)
        # What to watch: learnt from the sensors' own messages.
        from sensor_msgs.msg import LaserScan

        from downstream_perception.msg import DetectedObjectArray

        self.detection_stamps: dict[int, list[Any]] = {}
        rospy.Subscriber("/bench/scan", LaserScan, self.on_scan, queue_size=10)
        rospy.Subscriber(
            "/bench/detections", DetectedObjectArray, self.on_detections, queue_size=10
        )

    def on_scan(self, msg: Any) -> None:
        """Watches the blip this scan shows (the one whose bearing returns short of the wall)."""
        for k, x in enumerate(BLIPS):
            bearing = np.arctan2(BLIP_Y, x)
            i = int(round((bearing - msg.angle_min) / msg.angle_increment))
            if 0 <= i < len(msg.ranges) and msg.ranges[i] < np.hypot(x, BLIP_Y) + 0.05:
                self.watch(("scan", k), [msg.header.stamp], x, BLIP_Y)

    def on_detections(self, msg: Any) -> None:
        """Watches each new object from its first detection; from its min_hits-th (3rd) one on,
        measures from the first and from that confirming detection."""
        for d in msg.detections:
            j = int(d.truth_id)
            stamps = self.detection_stamps.setdefault(j, [])
            stamps.append(msg.header.stamp)
            if len(stamps) == 1:
                self.watch(("object", j), [], d.position.x, d.position.y, half=0)
            elif len(stamps) == 3:
                with self.lock:
                    if ("object", j) in self.pending:
                        self.pending[("object", j)][0][:] = [stamps[0], stamps[2]]
                        self.look_back(("object", j))

    def on_diagnostics(self, msg: Any) -> None:
        for status in msg.status:
            if not status.name.endswith("costmap: costmap"):
                continue
            for kv in status.values:
                if kv.key.startswith("data stamp to publish"):
                    with self.lock:
                        self.host[kv.key.split()[-2]] = float(kv.value)

    def watch(self, key: Any, stamps: list[Any], x: float, y: float, half: int = 1) -> None:
        r, c = cell(x, y)
        with self.lock:
            if key in self.pending:
                self.missed[key[0]] += 1
            self.pending[key] = (stamps, (slice(r - half, r + half + 1), slice(c - 2, c + 3)))
            self.look_back(key)

    def look_back(self, key: Any) -> None:
        """Measures `key` at the first message already received after its latest stamp whose
        cells show it LETHAL (the lock is held)."""
        stamps, (rows, cols) = self.pending[key]
        if not stamps:
            return
        since = max(stamps)
        for now, y, x, cells in self.recent:
            if now >= since and shows_lethal((rows, cols), y, x, cells):
                self.results[key[0]].append([(now - s).to_sec() for s in stamps])
                del self.pending[key]
                return

    def on_full(self, msg: Any) -> None:
        now = self.rospy.Time.now()
        with self.lock:
            self.grid = np.asarray(msg.data, dtype=np.int8).reshape(msg.info.height, -1).copy()
            self.recent.append((now, 0, 0, self.grid.copy()))
            self.check(now, 0, 0, self.grid)

    def on_update(self, msg: Any) -> None:
        now = self.rospy.Time.now()
        with self.lock:
            if self.grid is None:
                return
            patch = np.asarray(msg.data, dtype=np.int8).reshape(msg.height, msg.width)
            self.grid[msg.y : msg.y + msg.height, msg.x : msg.x + msg.width] = patch
            self.recent.append((now, msg.y, msg.x, patch))
            self.check(now, msg.y, msg.x, patch)

    def check(self, now: Any, y: int, x: int, cells: np.ndarray) -> None:
        """Measures each watched key this message (cells at row y, column x) shows LETHAL."""
        for key in list(self.pending):
            stamps, window = self.pending[key]
            if stamps and shows_lethal(window, y, x, cells):
                self.results[key[0]].append([(now - s).to_sec() for s in stamps])
                del self.pending[key]


def shows_lethal(window: tuple[slice, slice], y: int, x: int, cells: np.ndarray) -> bool:
    """Whether the cells (a costmap message's, at row y, column x) hold LETHAL in the window."""
    rows, cols = window
    r0, r1 = max(rows.start, y), min(rows.stop, y + cells.shape[0])
    c0, c1 = max(cols.start, x), min(cols.stop, x + cells.shape[1])
    return r0 < r1 and c0 < c1 and bool((cells[r0 - y : r1 - y, c0 - x : c1 - x] == 100).any())


def run(duration_s: float = 30.0, update_on_data: bool = False) -> dict[str, Any]:
    """One run of the nodelets on a private master; update_on_data: the costmap also updates
    and publishes as soon as new data changed it (besides its 10 Hz timer). Measured in a child
    process: rospy.init_node works once per process, and each run has a master of its own."""
    with multiprocessing.get_context("fork").Pool(1) as pool:
        return pool.apply(_run_here, (duration_s, update_on_data))


def _run_here(duration_s: float, update_on_data: bool) -> dict[str, Any]:
    from downstream_perception.ros.processes import free_port, stop_process

    port = free_port()
    os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
    procs = [
        subprocess.Popen(
            ["roscore", "-p", str(port)], stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT
        ),
    ]
    try:
        time.sleep(2.0)
        procs.append(
            subprocess.Popen(
                [
                    "roslaunch",
                    "-p",
                    str(port),
                    "downstream_perception",
                    "bench_latency.launch",
                    f"update_on_data:={str(update_on_data).lower()}",
                ],
                stdout=subprocess.DEVNULL,
                stderr=subprocess.STDOUT,
            )
        )
        return {"update_on_data": update_on_data, **measure(duration_s)}
    finally:
        for proc in reversed(procs):
            stop_process(proc)


def measure(duration_s: float) -> dict[str, Any]:
    import rospy
    from sensor_msgs.msg import LaserScan
    from tf2_ros import StaticTransformBroadcaster

    from downstream_perception.msg import DetectedObject, DetectedObjectArray
    from downstream_perception.ros.util import laser_scan, transform_stamped, wait_until

    rospy.init_node("bench_latency", disable_signals=True)
    static_tf = StaticTransformBroadcaster()
    now = rospy.Time.now()
    static_tf.sendTransform(
        [
            transform_stamped("map", "odom", now, x=1.0),
            transform_stamped("odom", "base_link", now, x=-1.0),
        ]
    )
    scans = rospy.Publisher("/bench/scan", LaserScan, queue_size=5)
    detections = rospy.Publisher("/bench/detections", DetectedObjectArray, queue_size=5)
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "probe.json")
        probe = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "--probe", out, str(duration_s + 60.0)]
        )
        try:
            # The costmap and the probe listen to both streams, the tracker to the detections.
            if not wait_until(
                lambda: scans.get_num_connections() >= 2 and detections.get_num_connections() >= 2,
                30.0,
            ):
                raise RuntimeError("bench_latency: the costmap or the probe never came up")
            time.sleep(2.0)  # the probe's first full costmap
            play(duration_s, scans, detections, laser_scan, DetectedObject, DetectedObjectArray)
            time.sleep(1.0)  # the last messages
            probe.terminate()
            probe.wait(timeout=30.0)
        finally:
            if probe.poll() is None:
                probe.kill()
        with open(out) as f:
            found = json.load(f)
    rospy.signal_shutdown("bench done")

    def stats(values: list[float]) -> dict[str, float]:
        a = 1e3 * np.asarray(values) if values else np.array([np.nan])
        return {
            "n": float(len(values)),
            "p50_ms": float(np.percentile(a, 50)),
            "p99_ms": float(np.percentile(a, 99)),
            "max_ms": float(a.max()),
        }

    scan = [r[0] for r in found["results"]["scan"]]
    first = [r[0] for r in found["results"]["object"]]
    confirm = [r[1] for r in found["results"]["object"] if len(r) > 1]
    return {
        "duration_s": duration_s,
        "scan": stats(scan),
        "scan_missed": float(found["missed"]["scan"]),
        "object_first": stats(first),
        "object_confirm": stats(confirm),
        "object_missed": float(found["missed"]["object"]),
        "host_data_to_publish_ms": found["host"],
    }


def play(
    duration_s: float,
    scans: Any,
    detections: Any,
    laser_scan: Any,
    detected_object: Any,
    detected_object_array: Any,
) -> None:
    """Plays scans (10 Hz, one blip each) and detections (15 Hz) for duration_s."""
    import rospy

    from downstream_perception.sim import Lidar, LidarConfig
    from downstream_perception.sim.world import World, box_segments

    lidar = Lidar(LidarConfig(num_beams=1440, noise_std_m=0.0))
    wall = [[-3.0, 3.5, 13.0, 3.5]]
    worlds = [
        World(segments=np.vstack([np.array(wall), box_segments(x, BLIP_Y, 0.06, 0.06)]))
        for x in BLIPS
    ]
    c = lidar.config
    stop = threading.Event()
    t0 = rospy.Time.now() + rospy.Duration(1.0)

    def scan_loop() -> None:
        rate = rospy.Rate(SCAN_HZ)
        seq = 0
        while not stop.is_set() and not rospy.is_shutdown():
            ranges = lidar.scan(worlds[seq % len(BLIPS)], (0.0, 0.0, 0.0))
            stamp = rospy.Time.now()
            scans.publish(
                laser_scan(stamp, "base_link", ranges, c.angle_min, c.angle_increment, 0.05, 20.0)
            )
            seq += 1
            rate.sleep()

    def detection_loop() -> None:
        rate = rospy.Rate(DETECTION_HZ)
        while not stop.is_set() and not rospy.is_shutdown():
            stamp = rospy.Time.now()
            t = (stamp - t0).to_sec()
            msg = detected_object_array()
            msg.header.stamp, msg.header.frame_id = stamp, "base_link"
            j = int(t // OBJECT_PERIOD_S) if t >= 0.0 else -1
            if j >= 0 and t - j * OBJECT_PERIOD_S < OBJECT_LIFE_S:
                d = detected_object(header=msg.header, kind=detected_object.POSITION, score=0.9)
                d.position.x, d.position.y = OBJECT_SLOTS[j % len(OBJECT_SLOTS)], OBJECT_Y
                d.position_covariance = [1e-4, 0.0, 0.0, 1e-4]  # base_link = map here
                d.size_x = d.size_y = 0.3
                d.truth_id = j
                msg.detections.append(d)
            detections.publish(msg)
            rate.sleep()

    threads = [threading.Thread(target=f, daemon=True) for f in (scan_loop, detection_loop)]
    for th in threads:
        th.start()
    time.sleep(duration_s)
    stop.set()
    for th in threads:
        th.join(timeout=2.0)


def probe_main(out: str, run_s: float) -> None:
    """--probe: follows the costmap on the master in ROS_MASTER_URI until SIGTERM (at most run_s
    seconds), then writes what it measured (receive time minus stamp, s) to `out` as JSON."""
    import rospy

    rospy.init_node("bench_latency_probe", disable_signals=True)
    probe = Probe()
    done = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: done.set())  # the sensors' process: play is over
    done.wait(run_s)
    with probe.lock:
        found = {"results": probe.results, "missed": probe.missed, "host": dict(probe.host)}
    with open(out, "w") as f:
        json.dump(found, f)
    rospy.signal_shutdown("probe done")


def markdown(runs: list[dict[str, Any]]) -> list[str]:
    def row(mode: str, name: str, s: dict[str, float]) -> str:
        figures = " | ".join(f"{s[k]:.1f}" for k in ("p50_ms", "p99_ms", "max_ms"))
        return f"| {mode} | {name} | {int(s['n'])} | {figures} |"

    rows: list[str] = []
    missed: list[str] = []
    for r in runs:
        mode = "update_on_data" if r.get("update_on_data") else "timer (10 Hz)"
        rows += [
            row(mode, "scan stamp -> its returns in the costmap", r["scan"]),
            row(mode, "first detection -> tracked cells (incl. min_hits = 3)", r["object_first"]),
            row(mode, "confirming detection -> tracked cells", r["object_confirm"]),
        ]
        host = r.get("host_data_to_publish_ms", {})
        if host:
            rows.append(
                f"| {mode} | costmap's own: oldest data stamp -> handed to the publisher "
                f"(last 200) | | {host.get('p50', float('nan')):.1f} | "
                f"{host.get('p99', float('nan')):.1f} | {host.get('max', float('nan')):.1f} |"
            )
        missed.append(
            f"{mode}: {int(r['scan_missed'])} scans, {int(r['object_missed'])} objects never seen"
        )
    duration = runs[0]["duration_s"] if runs else 0.0
    return [
        "## End-to-end latency (tracker + costmap nodelets, one manager)",
        "",
        f"Scans at {SCAN_HZ:.0f} Hz, detections at {DETECTION_HZ:.0f} Hz for {duration:.0f} s "
        "per mode; the costmap (obstacle layer with tracked-object clearing, tracked-obstacle "
        "layer, inflation) updates and publishes on a 10 Hz timer (costmap_2d's way: up to "
        "100 ms of each figure is the wait for the next update and publish), and with "
        "`update_on_data: true` also right after each scan or track array that changed it. "
        "Measured at the subscriber: receive time of the first costmap message showing it, "
        "minus the stamp.",
        "",
        "| mode | from | samples | p50 (ms) | p99 (ms) | max (ms) |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        "Replaced before they appeared: " + "; ".join(missed) + ".",
        "",
    ]


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--probe":
        probe_main(sys.argv[2], float(sys.argv[3]))
    else:
        print("\n".join(markdown([run(), run(update_on_data=True)])))
