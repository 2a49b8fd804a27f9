"""Seam health of a replayed bag, from the bag's own tf and stamps (no ROS needed here): how old
the transform that places each input message was, how far that age throws an obstacle at the
reference range while the robot turns (the handoff's expected smear), and how the localisation
correction map <- odom behaved (the handoff's CorrectionMonitor). The same limits and helpers
as the handoff nodelet (SeamLimits, expected_smear, CorrectionMonitor), so the report and a
live robot's seam_health topic judge alike."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import downstream_perception as dp


@dataclass
class RobotMotion:
    """The robot in a fixed frame at evenly spaced bag times (s)."""

    t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    xy: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    yaw_rad: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def yaw_rate_rps(self) -> np.ndarray:
        """d(yaw)/dt over the unwrapped yaw (rad/s); zeros with fewer than two samples."""
        if len(self.t_s) < 2:
            return np.zeros(len(self.t_s))
        return np.gradient(np.unwrap(self.yaw_rad), self.t_s)

    def travelled_m(self) -> np.ndarray:
        """Path length from the first sample (m)."""
        if len(self.xy) < 2:
            return np.zeros(len(self.xy))
        steps = np.linalg.norm(np.diff(self.xy, axis=0), axis=1)
        return np.concatenate(([0.0], np.cumsum(steps)))


@dataclass
class InputSeam:
    """One input topic: per message, its stamp (s), transform age (s) and expected smear (m)."""

    stamps_s: np.ndarray
    ages_s: np.ndarray
    smear_m: np.ndarray

    def p95(self, values: np.ndarray) -> float:
        return float(np.percentile(values, 95)) if len(values) else float("nan")


@dataclass
class SeamReport:
    limits: Any  # dp.SeamLimits
    inputs: dict[str, InputSeam]
    correction_t_s: np.ndarray  # bag times of the map <- odom samples (s)
    correction_m: np.ndarray  # |translation of map <- odom| (m)
    correction_findings: list[str]

    def lines(self) -> list[str]:
        lim = self.limits
        out = ["", "## Seam health (the handoff's limits)", ""]
        for topic, s in sorted(self.inputs.items()):
            age, smear = s.p95(s.ages_s), s.p95(s.smear_m)
            warn = []
            if age > lim.max_transform_age_s:
                warn.append(f"age above {lim.max_transform_age_s * 1e3:.0f} ms")
            if smear > lim.max_smear_m:
                warn.append(f"smear above {lim.max_smear_m:.3f} m")
            out.append(
                f"- `{topic}`: p95 transform age {age * 1e3:.1f} ms, p95 expected smear at "
                f"{lim.reference_range_m:g} m {smear:.3f} m"
                + (f" (WARN: {'; '.join(warn)})" if warn else "")
            )
        if not self.inputs:
            out.append("- no input message came after a /tf message: no transform ages")
        if len(self.correction_m):
            out.append(
                f"- map <- odom: {len(self.correction_m)} samples, |correction| "
                f"{self.correction_m.min():.3f}-{self.correction_m.max():.3f} m, last "
                f"{self.correction_m[-1]:.3f} m"
            )
            out += [f"- map <- odom WARN: {f}" for f in self.correction_findings]
        else:
            out.append("- map <- odom: not in the bag's tf (no localisation correction to judge)")
        return out


def input_seams(
    stamps_s: dict[str, list[float]],
    ages_s: dict[str, list[float]],
    motion: RobotMotion,
    limits: Any,
) -> dict[str, InputSeam]:
    """Expected smear per input message: the robot's yaw rate at the message's stamp and the
    message's transform age (only a positive age, data newer than the newest transform, throws
    the obstacle) at the reference range."""
    rate = motion.yaw_rate_rps()
    out = {}
    for topic, stamps in stamps_s.items():
        t = np.asarray(stamps, dtype=float)
        age = np.asarray(ages_s.get(topic, []), dtype=float)
        if len(t) == 0 or len(t) != len(age):
            continue
        yaw_rate = np.interp(t, motion.t_s, rate) if len(motion.t_s) else np.zeros(len(t))
        smear = np.array(
            [
                dp.expected_smear(limits.reference_range_m, float(w), max(float(a), 0.0))
                for w, a in zip(yaw_rate, age, strict=True)
            ]
        )
        out[topic] = InputSeam(t, age, smear)
    return out


def correction_findings(
    t_s: np.ndarray, correction_m: np.ndarray, travelled_m: np.ndarray
) -> list[str]:
    """The handoff's CorrectionMonitor over the samples (defaults: 120 s window, 2 m ...)."""
    if len(t_s) == 0:
        return []
    monitor = dp.CorrectionMonitor()
    monitor.add_many(
        np.asarray(t_s, float), np.asarray(correction_m, float), np.asarray(travelled_m, float)
    )
    return list(monitor.findings())


def render_seam_health(report: SeamReport, start_s: float, out: Path) -> Path | None:
    """Expected smear per input over the bag, and |map <- odom| when the bag has it."""
    if not report.inputs and not len(report.correction_m):
        return None
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = 2 if len(report.correction_m) else 1
    fig, axes = plt.subplots(rows, 1, figsize=(8, 2.6 * rows + 0.6), squeeze=False)
    ax = axes[0][0]
    for topic, s in sorted(report.inputs.items()):
        ax.plot(s.stamps_s - start_s, s.smear_m, ".", ms=3, label=topic)
    ax.axhline(report.limits.max_smear_m, color="#d62728", lw=1, ls="--", label="max_smear_m")
    ax.set_ylim(bottom=0.0)
    ax.set_ylabel(f"expected smear at {report.limits.reference_range_m:g} m (m)")
    ax.legend(fontsize="small")
    if rows == 2:
        ax2 = axes[1][0]
        ax2.plot(report.correction_t_s - start_s, report.correction_m, "-", color="#1f77b4")
        ax2.set_ylabel("|map <- odom| (m)")
    axes[-1][0].set_xlabel("bag time (s)")
    fig.tight_layout()
    fig.savefig(out, dpi=100)
    plt.close(fig)
    return out
