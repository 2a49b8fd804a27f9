"""What a replay writes: the costmap as a map_server map and a PNG, the tracks as CSV and a plot,
transform-age histograms, and the report (Markdown, and HTML with the images inline)."""

from __future__ import annotations

import base64
import csv
import html
import re
from pathlib import Path
from typing import Any

import numpy as np
import yaml

# map_server's thresholds (map_saver --occ 65 --free 25; the YAML's occupied_thresh 0.65 and
# free_thresh 0.196) and its grey levels.
OCCUPIED_MIN, FREE_MAX = 65, 25
PGM_FREE, PGM_OCCUPIED, PGM_UNKNOWN = 254, 0, 205
TRACK_COLUMNS = [
    "stamp", "id", "state", "label", "x", "y", "vx", "vy",
    "pos_cov_xx", "pos_cov_xy", "pos_cov_yx", "pos_cov_yy",
    "vel_cov_xx", "vel_cov_xy", "vel_cov_yx", "vel_cov_yy",
    "size_x", "size_y", "score", "truth_id",
]  # fmt: skip
STATES = {0: "tentative", 1: "confirmed", 2: "coasting"}


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
    header = f"P5\n# downstream_perception replay\n{width} {height}\n255\n".encode()
    pgm_path.write_bytes(header + pgm.tobytes())
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


def track_row(stamp: float, track: Any) -> list[Any]:
    """One CSV row of a downstream_perception/TrackedObject."""
    return [
        f"{stamp:.6f}", track.id, STATES.get(track.state, str(track.state)), track.label,
        track.position.x, track.position.y, track.velocity.x, track.velocity.y,
        *track.position_covariance, *track.velocity_covariance,
        track.size_x, track.size_y, track.score, track.truth_id,
    ]  # fmt: skip


class TrackLog:
    """tracks.csv written as the tracks arrive, and the confirmed tracks' trajectories for the
    plot, thinned (every 2nd, 4th, ... point) to at most `max_points`: memory stays bounded
    however long the bag."""

    def __init__(self, path: Path, max_points: int = 200_000) -> None:
        self.path, self.max_points = path, max_points
        self._file = path.open("w", newline="")
        self._writer = csv.writer(self._file)
        self._writer.writerow(TRACK_COLUMNS)
        self.rows = 0
        self.trajectories: dict[int, list[tuple[float, float]]] = {}
        self._points, self._stride, self._confirmed_rows = 0, 1, 0

    def add(self, stamp: float, tracks: list[Any]) -> None:
        for track in tracks:
            self._writer.writerow(track_row(stamp, track))
            self.rows += 1
            if track.state != 1:
                continue
            self._confirmed_rows += 1
            if self._confirmed_rows % self._stride == 0:
                xy = (track.position.x, track.position.y)
                self.trajectories.setdefault(int(track.id), []).append(xy)
                self._points += 1
            if self._points > self.max_points:
                for key, xy in self.trajectories.items():
                    self.trajectories[key] = xy[::2]
                self._points = sum(len(xy) for xy in self.trajectories.values())
                self._stride *= 2

    def close(self) -> None:
        self._file.close()


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def render_map_png(
    grid: np.ndarray | None,
    resolution: float,
    origin: tuple[float, float],
    path_xy: np.ndarray,
    trajectories: dict[int, list[tuple[float, float]]],
    out: Path,
    title: str,
) -> Path:
    """The costmap (if any) with the robot's path and the confirmed tracks coloured by id."""
    import matplotlib

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9, 6))
    if grid is not None:
        height, width = grid.shape
        extent = (
            origin[0],
            origin[0] + width * resolution,
            origin[1],
            origin[1] + height * resolution,
        )
        cmap = matplotlib.colormaps["gray_r"].copy()
        cmap.set_bad("#7fb2b2")
        shown = np.where(grid < 0, np.nan, grid.astype(float))
        ax.imshow(
            shown,
            origin="lower",
            extent=extent,
            cmap=cmap,
            vmin=0,
            vmax=100,
            interpolation="nearest",
        )
    if len(path_xy):
        ax.plot(path_xy[:, 0], path_xy[:, 1], "-", color="#d62728", lw=1.5, label="robot path")
        ax.plot(*path_xy[0], "o", color="#2ca02c", label="start")
    by_id = trajectories
    colours = matplotlib.colormaps["tab20"]
    for k, (_, xy) in enumerate(sorted(by_id.items())):
        points = np.asarray(xy)
        ax.plot(points[:, 0], points[:, 1], "-", lw=1.0, color=colours(k % 20))
    if by_id:
        ax.plot([], [], "-", color=colours(0), label=f"{len(by_id)} confirmed tracks (colour = id)")
    if len(path_xy) or by_id:
        ax.legend(loc="upper right")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def render_histograms(ages: dict[str, list[float]], out: Path) -> Path | None:
    if not any(ages.values()):
        return None
    plt = _pyplot()
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


HISTOGRAM_BIN = re.compile(r"^([0-9.e+]+)-([0-9.e+]+|inf):([0-9]+)$")
HISTOGRAM_KEY = re.compile(r"^(.*) histogram \((ms|us)\)$")


def parse_histogram(text: str) -> list[tuple[float, float, int]]:
    """A nodelet's LogHistogram::encode() ("lower-upper:count ...") as (lower, upper, count)."""
    bins = []
    for item in text.split():
        m = HISTOGRAM_BIN.match(item)
        if m is None:
            raise ValueError(f"not a histogram bin: {item!r}")
        bins.append((float(m.group(1)), float(m.group(2)), int(m.group(3))))
    return bins


def processing_histograms(diagnostics: dict[str, str]) -> dict[str, list[tuple[float, float, int]]]:
    """Every "<name> histogram (ms|us)" the nodelets reported, in ms, by "<status>: <name>"."""
    out = {}
    for key, value in diagnostics.items():
        m = HISTOGRAM_KEY.match(key)
        if m is None or not value:
            continue
        scale = 1e-3 if m.group(2) == "us" else 1.0
        out[m.group(1)] = [(lo * scale, hi * scale, n) for lo, hi, n in parse_histogram(value)]
    return out


def render_processing_times(
    histograms: dict[str, list[tuple[float, float, int]]], out: Path
) -> Path | None:
    """Per-message processing time of each nodelet (and observation source), whole replay."""
    if not histograms:
        return None
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    for name, bins in sorted(histograms.items()):
        # Overflow bins have no finite upper edge: drawn one bin wide.
        edges = [(lo, hi if np.isfinite(hi) else lo * 10**0.25, n) for lo, hi, n in bins]
        xs = np.array([[max(lo, 1e-4), hi] for lo, hi, _ in edges]).ravel()
        ys = np.repeat([n for _, _, n in edges], 2)
        ax.step(xs, ys, where="post", label=name)
    ax.set_xscale("log")
    ax.set_xlabel("processing time per message or update (ms, 4 bins per decade)")
    ax.set_ylabel("messages")
    ax.legend(fontsize="small")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out


def _image_html(path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode()
    return f'<img alt="{html.escape(path.name)}" src="data:image/png;base64,{data}">'


def write_report(out: Path, lines: list[str], images: list[tuple[str, Path]]) -> tuple[Path, Path]:
    """report.md (images linked) and report.html (the same text, images inline)."""
    md_lines = list(lines)
    for title, image in images:
        md_lines += ["", f"## {title}", "", f"![{title}]({image.name})"]
    md = out / "report.md"
    md.write_text("\n".join(md_lines) + "\n")
    body = f"<pre>{html.escape(chr(10).join(lines))}</pre>"
    for title, image in images:
        body += f"<h2>{html.escape(title)}</h2>{_image_html(image)}"
    page = out / "report.html"
    page.write_text(
        "<!doctype html><html><head><meta charset='utf-8'><title>replay</title></head>"
        f"<body>{body}</body></html>\n"
    )
    return md, page
