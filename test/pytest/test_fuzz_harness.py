"""The fuzz harness's bookkeeping (test/fuzz/fuzz_harness.py), with stand-in targets: a crash
(os.abort), a hang (an endless loop), garbage (NaN where a number is due), clean and unclear
errors, and a memory hog. Also: every binding entry point has a fuzz target, and every target's
generator runs."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

SCRIPTS = Path(__file__).resolve().parents[2] / "test" / "fuzz"
sys.path.insert(0, str(SCRIPTS))

import fuzz_harness as harness  # noqa: E402

SPEC = f"{Path(__file__).resolve()}:stand_in_targets"
SEED = 5


def _value(rng: np.random.Generator) -> dict[str, Any]:
    return {"x": float(rng.uniform(0, 1))}


def _endless(args: dict[str, Any]) -> None:
    while True:
        pass


def _must_be_finite(args: dict[str, Any], result: Any) -> str | None:
    return None if math.isfinite(result) else f"result {result}"


def _raise(error: BaseException) -> Any:
    def call(args: dict[str, Any]) -> Any:
        raise error

    return call


def _hog(args: dict[str, Any]) -> Any:
    return np.ones(1 << 30)  # 8 GB: far above the test's memory limit


def _broken_generator(rng: np.random.Generator) -> dict[str, Any]:
    raise KeyError("oops")


def stand_in_targets() -> list[harness.Target]:
    T = harness.Target
    return [
        T("ok", _value, lambda a: a["x"], _must_be_finite),
        T("abort", _value, lambda a: os.abort()),
        T("hang", _value, _endless),
        T("nan", _value, lambda a: float("nan"), _must_be_finite),
        T("clean", _value, _raise(ValueError("resolution must be positive, got -1"))),
        T("bare", _value, _raise(ValueError())),
        T("runtime", _value, _raise(RuntimeError("Unable to cast Python instance"))),
        T(
            "internal",
            _value,
            _raise(ValueError("cannot create std::vector larger than max_size()")),
        ),
        T("driver_died", _value, _raise(harness.TargetCrashed("driver killed by SIGSEGV"))),
        T("bad_generator", _broken_generator, lambda a: 0.0),
        T("hog", _value, _hog),
    ]


# Under make test-sanitize the ASan runtime is preloaded: it reserves terabytes of address
# space, so the harness limits memory by RSS there (a hog is then killed, not refused).
UNDER_ASAN = "libasan" in os.environ.get("LD_PRELOAD", "")


def run(tasks: list[tuple[str, int]], **kwargs: Any) -> dict[tuple[str, int], harness.CaseResult]:
    options = {"workers": 2, "timeout_s": 3.0, "memory_mb": 1024, "batch": 4, **kwargs}
    results = harness.run_campaign(SPEC, tasks, SEED, **options)
    assert sorted((r.target, r.index) for r in results) == sorted(tasks), "one result per case"
    return {(r.target, r.index): r for r in results}


def test_each_outcome_is_classified() -> None:
    names = [t.name for t in stand_in_targets() if not (UNDER_ASAN and t.name == "hog")]
    results = run([(name, 0) for name in names])
    outcome = {name: results[(name, 0)].outcome for name in names}
    expected = {
        "ok": "ok",
        "abort": "crash",
        "hang": "hang",
        "nan": "garbage",
        "clean": "error",
        "bare": "unclear",
        "runtime": "unclear",
        "internal": "unclear",
        "driver_died": "crash",
        "bad_generator": "harness",
        "hog": "unclear",  # MemoryError under the address-space limit, not a dead machine
    }
    if UNDER_ASAN:
        expected.pop("hog")
    assert outcome == expected
    assert "SIGABRT" in results[("abort", 0)].detail
    assert results[("nan", 0)].detail == "result nan"
    assert "resolution must be positive" in results[("clean", 0)].detail
    if not UNDER_ASAN:
        assert "MemoryError" in results[("hog", 0)].detail


def test_cases_queued_behind_a_crash_and_a_hang_still_run() -> None:
    tasks = [("ok", i) for i in range(3)] + [("abort", 0), ("hang", 0)]
    tasks += [("ok", i) for i in range(3, 12)]
    results = run(tasks, workers=1, batch=8)
    assert results[("abort", 0)].outcome == "crash"
    assert results[("hang", 0)].outcome == "hang"
    assert all(results[("ok", i)].outcome == "ok" for i in range(12))


def test_a_case_is_a_function_of_seed_target_and_index() -> None:
    def draw(seed: int, name: str, index: int) -> float:
        return float(harness.case_rng(seed, name, index).random())

    assert draw(1, "a", 3) == draw(1, "a", 3)
    assert len({draw(1, "a", 3), draw(2, "a", 3), draw(1, "b", 3), draw(1, "a", 4)}) == 4


def test_tally_and_closing_line_count_every_outcome() -> None:
    names = ["ok", "ok", "abort", "hang", "nan", "clean", "bare"]
    results = [
        harness.CaseResult(n, i, o, "")
        for i, (n, o) in enumerate(
            zip(names, ["ok", "ok", "crash", "hang", "garbage", "error", "unclear"], strict=True)
        )
    ]
    table = harness.tally(results)
    assert table["ok"]["cases"] == 2 and table["ok"]["ok"] == 2
    assert table["abort"]["crash"] == 1 and table["hang"]["hang"] == 1
    line = harness.closing_line(table)
    assert line.startswith("fuzz: 7 cases, 1 crashes, 1 hangs, 1 garbage")
    assert "1 clean errors, 1 unclear errors" in line
    rows = {line.split()[0]: line.split()[1:] for line in harness.format_table(table).splitlines()}
    assert rows["entry"][1:] == ["cases", *harness.OUTCOMES]
    assert (
        rows["ok"][:2] == ["2", "2"] and rows["abort"][harness.OUTCOMES.index("crash") + 1] == "1"
    )


@pytest.fixture(scope="module")
def fuzz_targets() -> Any:
    import fuzz_targets as module

    return module


def test_every_generator_runs(fuzz_targets: Any) -> None:
    for target in fuzz_targets.targets():
        for index in range(40):
            args = target.generate(harness.case_rng(SEED, target.name, index))
            assert isinstance(args, dict), target.name


def test_every_binding_entry_point_has_a_fuzz_target(fuzz_targets: Any) -> None:
    core = pytest.importorskip("downstream_perception._core")
    # Return values, enums and constants: reached through the targets, nothing to call.
    not_called = {
        "IntegrationStats",
        "TrackerStats",
        "TsdfIntegrationStats",
        "EsdfUpdateStats",
        "TrackState",
    }
    public = {
        name
        for name in dir(core)
        if not name.startswith("_") and callable(getattr(core, name)) and name not in not_called
    }
    covered = {name for t in fuzz_targets.targets() for name in t.covers}
    assert public - covered == set(), "entry points without a fuzz target"
