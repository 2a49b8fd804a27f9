#!/usr/bin/env python3
"""Headless demo: the simulated robot drives the warehouse aisle, the costmap nodelet builds the
log-odds obstacle layer live; writes an rviz screenshot (Xvfb, off-screen) and a short report.

Usage: make demo   (or, in a sourced workspace: python3 scripts/demo.py --out out)
"""

from __future__ import annotations

import argparse
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def free_display() -> int:
    for n in range(77, 200):
        if not Path(f"/tmp/.X{n}-lock").exists() and not Path(f"/tmp/.X11-unix/X{n}").exists():
            return n
    raise RuntimeError("no free X display number")


class Demo:
    """Starts Xvfb and roslaunch, collects what the costmap publishes, cleans up."""

    def __init__(self, out: Path, timeout_s: float, rviz: bool) -> None:
        self.out = out
        self.timeout_s = timeout_s
        self.rviz = rviz and shutil.which("Xvfb") is not None
        self.procs: list[subprocess.Popen[bytes]] = []
        self.costmap: Any = None  # a CostmapClient once ROS is up
        self.diagnostics: dict[str, dict[str, str]] = {}
        self.sim_done = False

    def start(self) -> None:
        port = free_port()
        os.environ["ROS_MASTER_URI"] = f"http://localhost:{port}"
        if self.rviz:
            display = free_display()
            os.environ["DISPLAY"] = f":{display}"
            os.environ["LIBGL_ALWAYS_SOFTWARE"] = "1"
            self.procs.append(
                subprocess.Popen(
                    ["Xvfb", f":{display}", "-screen", "0", "1280x720x24", "-nolisten", "tcp"],
                    stdout=subprocess.DEVNULL,
                    stderr=subprocess.DEVNULL,
                )
            )
            time.sleep(1.0)
        log = open(self.out / "demo_launch.log", "wb")  # noqa: SIM115 (closed with the process)
        self.procs.append(
            subprocess.Popen(
                [
                    "roslaunch",
                    "-p",
                    str(port),
                    "downstream_perception",
                    "demo.launch",
                    f"rviz:={'true' if self.rviz else 'false'}",
                ],
                stdout=log,
                stderr=subprocess.STDOUT,
            )
        )

    def listen(self) -> None:
        import rospy
        from diagnostic_msgs.msg import DiagnosticArray
        from std_msgs.msg import Bool

        from downstream_perception.costmap_client import CostmapClient

        deadline = time.time() + 30.0
        while True:
            try:
                rospy.get_master().getPid()
                break
            except Exception:
                if time.time() > deadline:
                    raise RuntimeError(
                        "the ROS master did not come up; see demo_launch.log"
                    ) from None
                time.sleep(0.3)
        rospy.init_node("demo_report", anonymous=True, disable_signals=True)

        def on_diag(msg: DiagnosticArray) -> None:
            for status in msg.status:
                self.diagnostics[status.name] = {kv.key: kv.value for kv in status.values}
                self.diagnostics[status.name]["_summary"] = status.message

        def on_done(msg: Bool) -> None:
            self.sim_done = self.sim_done or bool(msg.data)

        self.costmap = CostmapClient("/costmap/costmap")  # full grid + ~costmap_updates
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag, queue_size=10)
        rospy.Subscriber("/sim_done", Bool, on_done, queue_size=1)

    def wait_for_run(self) -> float:
        t0 = time.time()
        while not self.sim_done:
            if time.time() - t0 > self.timeout_s:
                raise RuntimeError(f"the simulated run did not finish in {self.timeout_s} s")
            if self.procs[-1].poll() is not None:
                raise RuntimeError("roslaunch exited early; see demo_launch.log")
            time.sleep(0.2)
        run_s = time.time() - t0
        settle = time.time()
        while self.costmap.last_change_wall < settle + 1.0 and time.time() - settle < 10.0:
            time.sleep(0.2)  # one more costmap after the last scans
        return run_s

    def screenshot(self) -> Path | None:
        if not self.rviz:
            return None
        win = subprocess.run(
            ["xdotool", "search", "--sync", "--name", " - RViz$"],
            capture_output=True,
            text=True,
            timeout=60,
            check=False,
        ).stdout.split()
        if not win:
            print("demo: no rviz window found; no screenshot", file=sys.stderr)
            return None
        time.sleep(3.0)  # let rviz draw the latest costmap
        path = self.out / "demo.png"
        subprocess.run(["import", "-window", win[0], str(path)], check=True, timeout=60)
        return path

    def stop(self) -> None:
        for proc in reversed(self.procs):
            if proc.poll() is None:
                proc.send_signal(signal.SIGINT)
                try:
                    proc.wait(timeout=20)
                except subprocess.TimeoutExpired:
                    proc.kill()


def grid_summary(msg: Any) -> dict[str, Any]:
    from downstream_perception.sim import warehouse_aisle

    info = msg.info
    data = np.asarray(msg.data, dtype=np.int8).reshape(info.height, info.width)
    truth = warehouse_aisle().occupied_cells(
        info.origin.position.x, info.origin.position.y, info.resolution, info.width, info.height
    )
    lethal = data == 100
    # A true obstacle cell counts as found if a lethal cell lies within one cell of it.
    near = np.zeros_like(lethal)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            near |= np.roll(np.roll(lethal, dy, axis=0), dx, axis=1)
    seen_truth = truth & (data != -1)
    ys, xs = np.mgrid[0 : info.height, 0 : info.width]
    wx = info.origin.position.x + (xs + 0.5) * info.resolution
    wy = info.origin.position.y + (ys + 0.5) * info.resolution
    aisle = (np.abs(wy) < 1.0) & (wx > 1.0) & (wx < 17.0) & ~((np.abs(wx - 8.0) < 0.5) & (wy > 0.6))
    return {
        "cells": int(data.size),
        "free": int((data == 0).sum()),
        "occupied": int(lethal.sum()),
        "unknown": int((data == -1).sum()),
        "obstacle cells found (of those seen)": f"{(near & seen_truth).sum()} / {seen_truth.sum()}",
        "aisle cells free": f"{100.0 * (data[aisle] == 0).mean():.1f} %",
        "aisle cells lethal": f"{100.0 * (data[aisle] == 100).mean():.2f} %",
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out", help="output folder")
    parser.add_argument("--timeout", type=float, default=180.0, help="s to wait for the run")
    parser.add_argument("--no-rviz", action="store_true", help="skip rviz and the screenshot")
    args = parser.parse_args()
    out = Path(args.out).resolve()
    out.mkdir(parents=True, exist_ok=True)

    demo = Demo(out, args.timeout, rviz=not args.no_rviz)
    try:
        demo.start()
        demo.listen()
        run_s = demo.wait_for_run()
        png = demo.screenshot()
    finally:
        demo.stop()
    if demo.costmap is None or not demo.costmap.received:
        raise SystemExit("demo: no costmap was published; see out/demo_launch.log")

    summary = grid_summary(demo.costmap.message())
    layer = next((v for k, v in demo.diagnostics.items() if "layer obstacles" in k), {})
    costmap = next((v for k, v in demo.diagnostics.items() if k.endswith("costmap")), {})
    lines = [
        "# downstream_perception demo report",
        "",
        f"Synthetic warehouse aisle, robot driven 17 m at 1 m/s; run took {run_s:.1f} s.",
        "",
        f"![costmap]({png.name})" if png else "(no screenshot: Xvfb or rviz unavailable)",
        "",
        "| quantity | value |",
        "|---|---|",
    ]
    lines += [f"| {k} | {v} |" for k, v in summary.items()]
    for key in (
        "scan: messages integrated",
        "scan: messages rejected",
        "scan: integration time mean (ms)",
        "scan: integration time max (ms)",
        "scan: transform age at integration mean (s)",
        "scan: clear:mark ratio (all messages)",
        "max |log-odds|",
    ):
        if key in layer:
            lines.append(f"| {key} | {layer[key]} |")
    for key in ("update time mean (ms)", "update rate achieved (Hz)"):
        if key in costmap:
            lines.append(f"| costmap {key} | {costmap[key]} |")
    report = "\n".join(lines) + "\n"
    (out / "demo_report.md").write_text(report)
    print(report)
    print(f"demo: wrote {out / 'demo_report.md'}" + (f" and {png}" if png else ""))


if __name__ == "__main__":
    main()
