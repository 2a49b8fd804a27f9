#!/usr/bin/env python3
"""make fuzz: a fixed-seed fuzz campaign over every entry point of the compiled module and every
nodelet message check (test/fuzz/fuzz_targets.py), run by test/fuzz/fuzz_harness.py.

  python3 test/fuzz/fuzz.py                       # the short campaign (20,000 cases; CI)
  python3 test/fuzz/fuzz.py --cases 1000000       # the long one (make fuzz FUZZ_CASES=1000000)
  python3 test/fuzz/fuzz.py --only Tsdf --cases 2000
  python3 test/fuzz/fuzz.py --replay Tsdf:17      # one case again, with its arguments

Prints a table (per entry point: cases, ok, clean errors, unclear errors, garbage, crashes,
hangs) and a closing line "fuzz: N cases, C crashes, H hangs, G garbage (...)", writes a
reproducer for every crash, hang and garbage case into --out (default out/fuzz) and exits 1 if
there was any. Needs the workspace sourced (the module, sensor_msgs, the driver).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import fuzz_harness as harness  # noqa: E402
from fuzz_targets import targets  # noqa: E402

SPEC = f"{HERE / 'fuzz_targets.py'}:targets"
# Reproducer files per target and outcome (every case is counted; a systematic bug would
# otherwise write thousands of files).
MAX_REPRODUCERS = 20
# Crashes re-run alone in a fresh worker (a crash after heap damage done by an earlier case of
# the same worker would not reproduce alone).
MAX_CONFIRMATIONS = 3


def arguments_repr(args: Any) -> str:
    with np.printoptions(threshold=60, edgeitems=4, precision=17):
        return repr(args)


def slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_")


def interleaved(names: list[str], per_target: int) -> list[tuple[str, int]]:
    """Round robin over the targets, so that a slow target does not run alone at the end."""
    return [(name, index) for index in range(per_target) for name in names]


def write_reproducer(out: Path, seed: int, result: harness.CaseResult, confirmed: str) -> Path:
    by_name = {t.name: t for t in targets()}
    try:
        args: Any = by_name[result.target].generate(
            harness.case_rng(seed, result.target, result.index)
        )
    except Exception as error:  # noqa: BLE001 (a harness finding: its own generator failed)
        args = f"<the generator failed: {error!r}>"
    path = out / f"{result.outcome}-{slug(result.target)}-{result.index}.txt"
    path.write_text(
        f"entry point: {result.target}\n"
        f"outcome: {result.outcome}{confirmed}\n"
        f"seed: {seed}\ncase index: {result.index}\n"
        f"replay: python3 test/fuzz/fuzz.py --seed {seed} "
        f"--replay '{result.target}:{result.index}'\n"
        f"detail:\n{result.detail}\n\narguments:\n{arguments_repr(args)}\n"
    )
    return path


def replay(spec: str, seed: int, which: str, timeout_s: float, memory_mb: int) -> int:
    name, _, index_text = which.rpartition(":")
    by_name = {t.name: t for t in targets()}
    if name not in by_name:
        print(f"unknown entry point {name!r}; known: {', '.join(sorted(by_name))}")
        return 2
    index = int(index_text)
    args = by_name[name].generate(harness.case_rng(seed, name, index))
    print(f"{name} case {index} (seed {seed}):\n{arguments_repr(args)}")
    [result] = harness.run_campaign(spec, [(name, index)], seed, 1, timeout_s, memory_mb, 1)
    print(f"outcome: {result.outcome}\n{result.detail}")
    return 1 if result.outcome in harness.FAILING else 0


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--cases", type=int, default=20000, help="total cases (split evenly)")
    parser.add_argument("--seed", type=int, default=17)
    parser.add_argument("--workers", type=int, default=os.cpu_count() or 2)
    parser.add_argument("--timeout", type=float, default=10.0, help="s per case")
    parser.add_argument(
        "--memory-mb", type=int, default=2048, help="address-space limit per worker"
    )
    parser.add_argument("--out", type=Path, default=Path("out/fuzz"))
    parser.add_argument(
        "--only", action="append", default=[], help="entry points whose name contains this"
    )
    parser.add_argument(
        "--skip",
        action="append",
        default=[],
        help="entry points whose name contains this are skipped",
    )
    parser.add_argument("--replay", help="ENTRY_POINT:INDEX: run one case and print it")
    parser.add_argument("--list", action="store_true", help="list the entry points")
    args = parser.parse_args(argv)

    names = [t.name for t in targets()]
    if args.list:
        print("\n".join(names))
        return 0
    if args.replay:
        return replay(SPEC, args.seed, args.replay, args.timeout, args.memory_mb)
    if args.only:
        names = [n for n in names if any(o in n for o in args.only)]
    names = [n for n in names if not any(skip in n for skip in args.skip)]
    if not names:
        print("fuzz: no entry point left (--only / --skip)")
        return 2
    per_target = max(1, args.cases // len(names))
    tasks = interleaved(names, per_target)
    print(
        f"fuzz: {len(tasks)} cases over {len(names)} entry points, seed {args.seed}, "
        f"{args.workers} workers, {args.timeout:g} s and {args.memory_mb} MB per case"
    )
    start = time.monotonic()
    last_report = [start]

    def progress(done: int) -> None:
        now = time.monotonic()
        if now - last_report[0] > 30:
            last_report[0] = now
            print(f"  {done}/{len(tasks)} cases, {now - start:.0f} s", flush=True)

    results = harness.run_campaign(
        SPEC, tasks, args.seed, args.workers, args.timeout, args.memory_mb, progress=progress
    )
    elapsed = time.monotonic() - start

    args.out.mkdir(parents=True, exist_ok=True)
    for old in args.out.glob("*.txt"):
        old.unlink()
    findings = [r for r in results if r.outcome in harness.FAILING]
    findings.sort(key=lambda r: (r.target, r.outcome, r.index))
    written: dict[tuple[str, str], int] = defaultdict(int)
    confirmations: dict[str, int] = defaultdict(int)
    first_of: dict[tuple[str, str], harness.CaseResult] = {}
    for r in findings:
        key = (r.target, r.outcome)
        first_of.setdefault(key, r)
        if written[key] >= MAX_REPRODUCERS:
            continue
        written[key] += 1
        confirmed = ""
        if r.outcome == "crash" and confirmations[r.target] < MAX_CONFIRMATIONS:
            confirmations[r.target] += 1
            [again] = harness.run_campaign(
                SPEC, [(r.target, r.index)], args.seed, 1, args.timeout, args.memory_mb, 1
            )
            confirmed = (
                " (crashes again alone)"
                if again.outcome == "crash"
                else (f" (alone: {again.outcome}; earlier cases of the worker may have damaged it)")
            )
        write_reproducer(args.out, args.seed, r, confirmed)

    table = harness.tally(results)
    print(harness.format_table(table))
    if first_of:
        print("\nfirst finding per entry point and outcome:")
        for (target, outcome), r in sorted(first_of.items()):
            detail = r.detail.strip().splitlines()[0] if r.detail.strip() else ""
            print(f"  {outcome:<7} {target} #{r.index}: {detail[:160]}")
        print(f"reproducers: {args.out}/")
    unclear = [r for r in results if r.outcome == "unclear"]
    if unclear:
        kinds: dict[str, int] = defaultdict(int)
        for r in unclear:
            kinds[f"{r.target}: {r.detail.splitlines()[0][:100]}"] += 1
        print("\nunclear errors (most frequent):")
        for text, count in sorted(kinds.items(), key=lambda kv: -kv[1])[:10]:
            print(f"  {count:>6}  {text}")
    (args.out / "summary.json").write_text(
        json.dumps({"seed": args.seed, "elapsed_s": elapsed, "table": table}, indent=1)
    )
    print(f"\n{harness.closing_line(table)} in {elapsed:.0f} s")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
