"""The soak script's bookkeeping (bench/soak.py): RSS growth, the samples it reports, the rate
ramp's verdicts and the table. No ROS, no timing."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest


@pytest.fixture(scope="module")
def soak(bench_script: Callable[[str], Any]) -> Any:
    return bench_script("soak")


def result(soak: Any, rss: list[tuple[float, int]], name: str = "tsdf") -> Any:
    samples = [
        soak.Sample(t, kb, handled=int(15 * t), figures={"blocks": 100.0 + t}) for t, kb in rss
    ]
    return soak.SoakResult(name, "frames integrated", 15.0, samples)


def test_growth_is_relative_to_the_first_argument(soak: Any) -> None:
    assert soak.growth_pct(20_000, 21_000) == pytest.approx(5.0)
    assert soak.growth_pct(21_000, 20_000) == pytest.approx(-100.0 / 21.0)
    assert soak.growth_pct(20_000, 20_000) == 0.0
    assert math.isnan(soak.growth_pct(0, 100))


def test_growth_after_the_first_minute_uses_the_sample_at_one_minute(soak: Any) -> None:
    # Start-up growth (20 -> 40 MB in the first minute) does not count; 40 -> 41 MB after it does.
    r = result(soak, [(0.0, 20_480), (30.0, 30_720), (60.4, 40_960), (300.0, 41_984)])
    assert r.at(60.0).t_s == 60.4  # the first sample at or after 60 s
    assert r.growth_after_first_minute_pct == pytest.approx(2.5)
    # A soak shorter than a minute compares its last sample with itself.
    short = result(soak, [(0.0, 1000), (30.0, 1200)])
    assert short.at(60.0).t_s == 30.0
    assert short.growth_after_first_minute_pct == 0.0
    with pytest.raises(ValueError):
        soak.sample_at([], 0.0)


def test_trend_is_the_slope_after_the_first_minute(soak: Any) -> None:
    # Start-up (0 -> 60 s) is left out; then 1 MB per minute, minutes 2 and 3 0.5 MB above the line.
    rss = [(0.0, 1024), (60.0, 10_240), (120.0, 11_776), (180.0, 12_800), (240.0, 13_312)]
    assert soak.trend_mb_per_min(result(soak, rss).samples) == pytest.approx(1.0)
    assert math.isnan(soak.trend_mb_per_min(result(soak, rss[:2]).samples))


def test_rate_between_samples(soak: Any) -> None:
    a = soak.Sample(10.0, 1, handled=100, figures={"scans sent": 110.0})
    b = soak.Sample(20.0, 1, handled=1100, figures={"scans sent": 1210.0})
    assert soak.rate_between(a, b) == pytest.approx(100.0)
    assert soak.rate_between(a, b, "scans sent") == pytest.approx(110.0)
    assert math.isnan(soak.rate_between(b, a))


def counters(soak: Any, t: float, n: int, **kw: Any) -> Any:
    """n scans sent, received and integrated by time t; 10 updates per second; 2 ms latency."""
    c = {"sent": n, "received": n, "integrated": n, "updates": int(10 * t), "skipped": 0}
    c.update(kw)
    return soak.Counters(t_s=t, age_mean_s=c.pop("age", 0.002), **c)


def test_judge_step_accepts_a_kept_rate_and_names_each_failure(soak: Any) -> None:
    a = counters(soak, 0.0, 0)
    ok = counters(soak, 4.0, 400, publish_age_s=[0.003, 0.001, 0.002])
    assert soak.judge_step(a, ok, 100.0, 10.0) is None
    figures = soak.step_figures(a, ok)
    assert figures["sent_hz"] == pytest.approx(100.0)
    assert figures["scan_latency_ms"] == pytest.approx(2.0)
    assert figures["publish_latency_ms"] == pytest.approx(2.0)  # the median

    def why(b: Any) -> str:
        verdict = soak.judge_step(a, b, 100.0, 10.0)
        assert verdict is not None
        return str(verdict)

    assert why(counters(soak, 4.0, 300)).startswith("feed limit")
    assert why(counters(soak, 4.0, 400, received=350, integrated=350)).startswith("integrated 350")
    assert "skipped" in why(counters(soak, 4.0, 400, skipped=3))
    assert why(counters(soak, 4.0, 400, updates=20)).startswith("update loop")
    # The diagnostics' latency is a mean over all scans: this window's scans took 60 ms.
    later = counters(soak, 8.0, 800, age=0.031)
    assert "scan latency 60 ms" in str(soak.judge_step(ok, later, 100.0, 10.0))
    slow = counters(soak, 4.0, 400, publish_age_s=[0.2, 0.3, 0.01])
    assert why(slow).startswith("publish latency 200 ms")
    # Scans in flight at a snapshot (2 % of those sent) are no failure.
    assert soak.judge_step(a, counters(soak, 4.0, 400, integrated=393), 100.0, 10.0) is None


def test_table_and_closing_line(soak: Any) -> None:
    grows = result(soak, [(0.0, 10_240), (60.0, 20_480), (600.0, 22_528)], name="tsdf")
    flat = result(soak, [(0.0, 10_240), (60.0, 20_480), (600.0, 20_480)], name="costmap")
    flat.ramp = [{"rate_hz": 10.0, "sent_hz": 10.0, "verdict": None}]
    flat.notes = ["held 10 Hz"]
    text = "\n".join(soak.markdown([flat, grows], "1.00, 1.00, 1.00"))
    rows = {line.split(" | ")[0]: line for line in text.splitlines() if line.startswith("| ")}
    # 20 -> 22 MB from minute 1 to 10: +10 %, 2/9 MB per minute.
    assert rows["| tsdf"].endswith("| 10.0 | 20.0 | 22.0 | +10.00 % | NO | +0.222 |")
    assert rows["| costmap"].endswith("| 10.0 | 20.0 | 20.0 | +0.00 % | yes | +0.000 |")
    assert "9,000 frames integrated" in rows["| tsdf"]
    assert "| blocks | 100 | 160 | 700 |" in text  # diagnostics at start, 1 min, end
    assert "| 10 | 10 | nan | nan | nan | yes |" in text  # the ramp's step
    assert "- held 10 Hz" in text
    line = soak.closing_line([flat, grows])
    assert line.startswith("soak: costmap 9,000 frames integrated at 15 Hz, RSS 10.0 -> 20.0")
    assert "tsdf" in line and "(+10.00 % after 1 min)" in line
    assert line.endswith("NOT all under 5 %")
    assert soak.closing_line([flat]).endswith("; all under 5 %")


def test_csv_has_every_sample_and_figure(soak: Any, tmp_path: Path) -> None:
    r = result(soak, [(0.0, 1000), (5.0, 1001)])
    r.samples[1].figures["OctoMap leaves"] = 7.0
    path = tmp_path / "soak.csv"
    soak.write_csv(path, r)
    lines = path.read_text().splitlines()
    assert lines[0] == "t_s,rss_kb,handled,OctoMap leaves,blocks"
    assert lines[1] == "0.0,1000,0,,100.0"
    assert lines[2] == "5.0,1001,75,7.0,105.0"


SMAPS = """\
55d0c0a00000-55d0c0b00000 rw-p 00000000 00:00 0                          [heap]
Rss:                2048 kB
AnonHugePages:         0 kB
7f0000000000-7f0000400000 rw-p 00000000 00:00 0
Size:               4096 kB
Rss:                3072 kB
AnonHugePages:      2048 kB
7f0000400000-7f0004000000 ---p 00000000 00:00 0
Rss:                   0 kB
7f0008200000-7f0008400000 rw-p 00000000 00:00 0
Rss:                1024 kB
AnonHugePages:      1024 kB
7f1000000000-7f1000100000 r-xp 00000000 08:01 1234                       /usr/lib/libx.so
Rss:                 512 kB
AnonHugePages:         0 kB
7ffd00000000-7ffd00021000 rw-p 00000000 00:00 0                          [stack]
Rss:                 128 kB
"""


def test_smaps_breakdown_sums_rss_by_kind_of_mapping(soak: Any) -> None:
    b = soak.smaps_breakdown(SMAPS)
    assert b["RSS heap (MB)"] == 2.0
    assert b["RSS malloc arenas (MB)"] == 3.0  # unnamed, at a 64 MiB-aligned address
    assert b["RSS anonymous (MB)"] == 1.0  # unnamed elsewhere
    assert b["RSS huge pages (MB)"] == 3.0  # of both, in transparent huge pages
    assert b["RSS files (MB)"] == 0.5
    assert b["RSS other (MB)"] == 0.125  # the stack
