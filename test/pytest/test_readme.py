"""The README's Python example runs as written and gives what its comments say."""

from __future__ import annotations

from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[2] / "README.md"


def test_readme_python_example_runs() -> None:
    text = README.read_text()
    assert "```python" in text
    code = text.split("```python", 1)[1].split("```", 1)[0]
    namespace: dict[str, object] = {}
    exec(compile(code, str(README), "exec"), namespace)  # noqa: S102
    states = namespace["occupancy"]
    assert isinstance(states, np.ndarray) and states.shape == (200, 200)
    stats = namespace["stats"]
    # 360 beams of 2 m: each marks its own cell (some share one), clearing dominates.
    assert 0 < stats.cells_marked <= 360
    assert stats.clear_mark_ratio() > 10
    assert namespace["scan"].shape == (1080,)
