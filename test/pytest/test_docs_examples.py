"""The Python examples of the README and of docs/ run as written and give what their comments
say."""

from __future__ import annotations

from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def run_blocks() -> list[dict[str, object]]:
    """Each ```python block of the README and docs/, run in a fresh namespace (stands alone)."""
    namespaces = []
    for document in DOCUMENTS:
        text = document.read_text()
        for code in (part.split("```", 1)[0] for part in text.split("```python")[1:]):
            namespace: dict[str, object] = {}
            exec(compile(code, str(document), "exec"), namespace)  # noqa: S102
            namespaces.append(namespace)
    assert len(namespaces) >= 6
    return namespaces


def test_readme_tracking_example_runs() -> None:
    namespace = next(ns for ns in run_blocks() if "tracker" in ns)
    assert round(float(namespace["overlap"]), 3) == 0.220
    assert list(namespace["kept"]) == [0]
    assert abs(float(namespace["gate"]) - 9.21) < 5e-3
    assert len(namespace["tracks"]["id"]) == 1


def test_readme_python_example_runs() -> None:
    namespace = next(ns for ns in run_blocks() if "occupancy" in ns)
    states = namespace["occupancy"]
    assert isinstance(states, np.ndarray) and states.shape == (200, 200)
    stats = namespace["stats"]
    # 360 beams of 2 m: each marks its own cell (some share one), clearing dominates.
    assert 0 < stats.cells_marked <= 360
    assert stats.clear_mark_ratio() > 10
    assert namespace["scan"].shape == (1080,)


def test_readme_tsdf_example_runs() -> None:
    namespace = next(ns for ns in run_blocks() if "tsdf" in ns)
    mesh = namespace["mesh"]
    assert len(mesh["triangles"]) > 1000
    # Vertices lie on the room's true surfaces (5 cm voxels, 5 frames).
    from downstream_perception.sim.depth_camera import room_scene

    error = np.abs(room_scene().signed_distance(mesh["vertices"].astype(float)))
    assert float(np.median(error)) < 0.005
    # The probe 1 m above the floor's centre is free space, more than mu (0.2 m) from anything.
    distance, weight = namespace["distance_m"], namespace["weight"]
    assert weight[0] == 0.0 or distance[0] > 0.0


def test_readme_esdf_example_runs() -> None:
    namespace = next(ns for ns in run_blocks() if "esdf_stats" in ns)
    assert not namespace["esdf_stats"].full  # the last of 8 updates was incremental
    np.testing.assert_allclose(namespace["distance_m"], [0.075], atol=1e-6)
    np.testing.assert_allclose(namespace["gradient"], [[0.0, 0.0, 1.0]], atol=1e-5)


def test_readme_handoff_example_runs() -> None:
    namespace = next(ns for ns in run_blocks() if "corridor" in ns)
    corridor = namespace["corridor"]
    assert sorted(map(tuple, corridor.tolist())) == [(x, 81) for x in range(142, 161)]
    cleared = set(map(tuple, namespace["cleared"].tolist()))
    assert (160, 81) in cleared and (161, 81) in cleared  # 6 cm back, 0.1 m margin around it
    assert abs(float(namespace["smear"]) - 0.2358) < 5e-4
