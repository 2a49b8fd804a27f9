"""Camera trajectories in the .log format of Open3D and the Redwood data sets: per frame a line of
three integers (frame ids), then the 4 x 4 camera-to-world matrix row by row."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def read_trajectory_log(path: Path) -> list[np.ndarray]:
    """The 4 x 4 camera-to-world matrices of a trajectory .log file, in file order."""
    rows = [line.split() for line in path.read_text().splitlines() if line.strip()]
    if len(rows) % 5 != 0:
        raise ValueError(f"{path}: {len(rows)} non-empty lines, expected 5 per frame")
    poses = []
    for k in range(0, len(rows), 5):
        matrix = np.array([[float(v) for v in row] for row in rows[k + 1 : k + 5]])
        if matrix.shape != (4, 4) or not np.all(np.isfinite(matrix)):
            raise ValueError(f"{path}: frame {k // 5} is not a finite 4 x 4 matrix")
        poses.append(matrix)
    return poses
