"""replay BAG [--config COSTMAP.yaml] [--tracker TRACKER.yaml] [--tsdf TSDF.yaml] --out DIR"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from downstream_perception.replay import outputs, seam
from downstream_perception.replay.bag import BagSummary
from downstream_perception.replay.pipeline import (
    Pipeline,
    ReplayError,
    costmap_capability,
    tracker_capability,
    tsdf_capability,
)
from downstream_perception.replay.run import ReplayOptions, ReplayResult, replay

# Every file a replay writes into --out: an earlier replay's are replaced only with --overwrite.
OUTPUTS = [
    Path(name)
    for name in ("costmap.pgm", "costmap.yaml", "tracks.csv", "mesh.ply", "octomap.bt", "map.png",
                 "transform_ages.png", "processing_times.png", "seam_health.png", "report.md",
                 "report.html")
]  # fmt: skip

DESCRIPTION = """Replay a recorded bag through the same nodelets and YAML as on the robot, and
collect what they made.

The nodelets (launch/costmap.launch, tracker.launch, tsdf.launch, one manager) run on a private
ROS master on simulated time taken from the bag: /use_sim_time, and the bag's /tf, /tf_static
and the configured input topics published in record order with /clock at each one's record
time, at --rate times real time. Writes to --out: the final costmap as a map_server map
(costmap.pgm + costmap.yaml, which the StaticLayer loads) and a PNG with the robot's path; the
tracks as tracks.csv; the TSDF's mesh.ply and octomap.bt; plots of the transform ages, the
processing times and the seam health (each input message's expected smear at the handoff's
reference range from the robot's yaw rate and the message's transform age; |map <- odom| with
the handoff's CorrectionMonitor findings); and report.md / report.html.

A bag that cannot be replayed (unreadable or not indexed, none of a capability's topics, a topic
of the wrong type, no tf joining the data to the frame it is needed in, a clock that jumps back)
is refused before anything starts, with the reason and exit status 2; so is a replay in which a
nodelet never subscribes or the costmap publishes nothing."""


def parse(argv: list[str] | None) -> argparse.Namespace:
    ap = argparse.ArgumentParser(
        prog="replay", description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument("bag", type=Path)
    ap.add_argument("--config", type=Path, help="costmap YAML (ours or a move_base costmap's)")
    ap.add_argument("--tracker", type=Path, help="tracker YAML")
    ap.add_argument("--tracker-detections", default="/detections", help="its input topic")
    ap.add_argument("--tsdf", type=Path, help="TSDF YAML")
    ap.add_argument("--tsdf-depth", default="/depth", help="<ns>/image and <ns>/camera_info")
    ap.add_argument("--tsdf-points", default="/points", help="its PointCloud2 topic")
    ap.add_argument("--out", type=Path, default=Path("out/replay"))
    ap.add_argument("--rate", type=float, default=4.0, help="x real time (0: as fast as it can)")
    ap.add_argument("--settle-s", type=float, default=2.0, help="sim s after the last message")
    ap.add_argument("--timeout-s", type=float, default=60.0, help="for nodelets to start/publish")
    ap.add_argument("--quiet", action="store_true", help="no progress bar")
    ap.add_argument("--overwrite", action="store_true", help="replace an earlier replay's files")
    args = ap.parse_args(argv)
    if not (args.config or args.tracker or args.tsdf):
        ap.error("name at least one of --config (costmap), --tracker, --tsdf")
    if not (math.isfinite(args.rate) and args.rate >= 0):
        ap.error("--rate must be >= 0")
    return args


def pipeline_of(args: argparse.Namespace) -> Pipeline:
    capabilities, robot_frame = [], "base_link"
    if args.config:
        costmap, robot_frame = costmap_capability(args.config)
        capabilities.append(costmap)
    if args.tracker:
        capabilities.append(tracker_capability(args.tracker, args.tracker_detections))
    if args.tsdf:
        capabilities.append(tsdf_capability(args.tsdf, args.tsdf_depth, args.tsdf_points))
    return Pipeline(capabilities, robot_frame)


def write_outputs(out: Path, pipeline: Pipeline, summary: BagSummary, result: ReplayResult) -> Path:
    files: dict[str, Path] = {}
    images: list[tuple[str, Path]] = []
    c = result.costmap
    if c is not None:
        files["map"], files["map yaml"] = outputs.write_map(
            c.grid, c.resolution, c.origin, out / "costmap"
        )
    trajectories = result.tracks.trajectories if result.tracks else {}
    if result.tracks is not None:
        files["tracks"] = result.tracks.path
    if c is not None or trajectories:
        title = "final costmap, robot path and tracks" if c is not None else "tracks"
        grid, res, origin = (c.grid, c.resolution, c.origin) if c else (None, 1.0, (0.0, 0.0))
        png = outputs.render_map_png(
            grid, res, origin, result.path_xy, trajectories, out / "map.png", title
        )
        images.append((title.capitalize(), png))
    ages = outputs.render_histograms(summary.transform_ages_s, out / "transform_ages.png")
    if ages is not None:
        images.append(("Transform ages", ages))
    if result.seam is not None:
        health = seam.render_seam_health(result.seam, summary.start_s, out / "seam_health.png")
        if health is not None:
            images.append(("Seam health: expected smear per message, map <- odom", health))
    histograms = outputs.processing_histograms(result.diagnostics)
    times = outputs.render_processing_times(histograms, out / "processing_times.png")
    if times is not None:
        images.append(("Processing time per message", times))
    md, _ = outputs.write_report(out, report_lines(pipeline, summary, result, files), images)
    return md


def report_lines(
    pipeline: Pipeline, summary: BagSummary, result: ReplayResult, files: dict[str, Path]
) -> list[str]:
    speed = summary.duration_s / result.wall_s if result.wall_s > 0 else math.inf
    nodelets = [f"{c.name} ({c.config.name}, frame `{c.frame}`)" for c in pipeline.capabilities]
    lines = [
        f"# Replay of `{summary.path.name}`",
        "",
        f"- bag: {summary.duration_s:.1f} s of data, {summary.messages} messages on "
        f"{len(summary.topics)} topics",
        f"- replayed in {result.wall_s:.1f} s of wall time: {speed:.1f}x real time",
        f"- nodelets: {', '.join(nodelets)}",
    ]
    if result.costmap is not None:
        g = result.costmap
        lethal = int((g.grid >= outputs.OCCUPIED_MIN).sum())
        free = int(((g.grid >= 0) & (g.grid <= outputs.FREE_MAX)).sum())
        lines.append(
            f"- costmap: {g.grid.shape[1]} x {g.grid.shape[0]} cells at {g.resolution:.3f} m; "
            f"lethal {lethal}, free {free}, unknown {int((g.grid < 0).sum())}"
        )
    if result.tracks is not None:
        ids = len(result.tracks.trajectories)
        lines.append(f"- tracks: {result.tracks.rows} rows, {ids} confirmed ids")
    lines += [f"- TSDF {what}: {where}" for what, where in result.saved.items()]
    lines += ["", "| topic | type | in the bag | replayed |", "|---|---|---|---|"]
    for topic, (kind, n) in sorted(summary.topics.items()):
        lines.append(f"| `{topic}` | {kind} | {n} | {result.messages.get(topic, 0)} |")
    rejected = {
        k: v for k, v in result.diagnostics.items() if "rejected" in k and v not in ("0", "")
    }
    lines += ["", "## Rejections (diagnostics)", ""]
    lines += [f"- {k}: {v}" for k, v in sorted(rejected.items())] or ["- none"]
    behind = tf_rejections(result.diagnostics)
    if behind:
        lines.append(f"- WARN: {behind_warning(behind)}")
    words = (
        "integration time",
        "transform age",
        "messages received",
        "integrated",
        "time (ms)",
        " p50 (",
        " p99 (",
    )
    timing = {
        k: v
        for k, v in result.diagnostics.items()
        if any(w in k for w in words) and "histogram" not in k  # the histograms are plotted
    }
    lines += ["", "## Processing (diagnostics: counts, means, maxima and percentiles)", ""]
    lines += [f"- {k}: {v}" for k, v in sorted(timing.items())] or ["- none reported"]
    if result.seam is not None:
        lines += result.seam.lines()
    lines += ["", "## Files", ""] + [f"- {k}: `{p.name}`" for k, p in files.items()]
    return lines


def tf_rejections(diagnostics: dict[str, str]) -> int:
    """Messages the nodelets refused for tf reasons (lookup failed, older than the cache)."""
    total = 0
    for key, value in diagnostics.items():
        if "rejected (tf" in key:
            try:
                total += int(value)
            except ValueError:
                continue
    return total


def behind_warning(count: int) -> str:
    return (
        f"{count} messages were rejected for tf reasons: the nodelets fell behind the bag's "
        "clock (a message processed after its transform left the tf cache); replay again at a "
        "lower --rate (on a real 2-D laser log, --rate 0 lost 507 of 906 scans, --rate 50 none)"
    )


def main(argv: list[str] | None = None) -> int:
    args = parse(argv)
    options = ReplayOptions(args.rate, args.settle_s, args.timeout_s, args.quiet, args.overwrite)
    try:
        pipeline = pipeline_of(args)
        earlier = [p.name for p in OUTPUTS if (args.out / p).exists()]
        if earlier and not args.overwrite:
            raise ReplayError(
                f"{args.out} holds an earlier replay ({', '.join(earlier)}): pass --overwrite to "
                "replace it, or choose another --out"
            )
        summary, result = replay(args.bag, pipeline, args.out, options)
    except ReplayError as e:
        print(f"replay: {e}", file=sys.stderr)
        return 2
    md = write_outputs(args.out, pipeline, summary, result)
    behind = tf_rejections(result.diagnostics)
    if behind:
        print(f"replay: WARN: {behind_warning(behind)}", file=sys.stderr)
    print(f"replay: {summary.duration_s:.1f} s of bag in {result.wall_s:.1f} s; report {md}")
    return 0
