"""pytest: the seam-health helpers through the bindings: the lesson's smear table, and the
map <- odom correction monitor on sawtooth, runaway and stuck-at-zero histories."""

from __future__ import annotations

import math

import numpy as np
import pytest

import downstream_perception as dp


def test_lesson_smear_table() -> None:
    # 90 deg/s x 30 ms at 5 m: 23.6 cm; 4.7 cm at 1 m and 47 cm at 10 m.
    assert dp.expected_smear(5.0, math.radians(90), 0.030) == pytest.approx(0.2358, abs=5e-5)
    ranges = np.array([1.0, 5.0, 10.0])
    smear = np.array([dp.expected_smear(r, math.radians(90), 0.030) for r in ranges])
    np.testing.assert_allclose(smear, ranges * math.tan(math.radians(2.7)), rtol=1e-12)
    assert dp.expected_smear(5.0, 0.0, 0.5) == 0.0


def histories() -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    t = np.arange(0.0, 60.0, 0.1)
    travelled = 0.5 * t
    return {
        "sawtooth": (t, 0.02 * np.mod(t, 10.0), travelled),
        "runaway": (t, 0.02 * t, travelled),
        "stuck": (t, np.zeros_like(t), travelled),
    }


def test_correction_monitor_tells_the_three_histories_apart() -> None:
    config = dp.CorrectionMonitorConfig()
    config.window_s = 60.0
    verdicts = {}
    for name, (t, c, d) in histories().items():
        monitor = dp.CorrectionMonitor(config)
        monitor.add_many(t, c, d)
        verdicts[name] = (monitor.resets, monitor.never_resets(), monitor.stuck_at_zero())
    assert verdicts["sawtooth"] == (5, False, False)
    assert verdicts["runaway"] == (0, True, False)
    assert verdicts["stuck"] == (0, False, True)
    with pytest.raises(ValueError):
        dp.CorrectionMonitor().add_many(np.zeros(3), np.zeros(2), np.zeros(3))
