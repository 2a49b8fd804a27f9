"""Fixed-seed fuzzing harness: worker subprocesses, time and memory limits, classification.

A campaign runs the cases of a list of `Target`s (name, argument generator, call, garbage check;
see test/fuzz/fuzz_targets.py) in worker subprocesses. A case is fully determined by
(seed, target name, case index): the worker regenerates its arguments from those three, so a
reproducer is the seed and the index, and `--replay` re-runs exactly that case.

Each case ends as one of
  ok        the call returned and the output passed the target's garbage check
  error     a clean refusal: ValueError, TypeError or IndexError with a message of our own
  unclear   an exception without a message, a MemoryError, a RuntimeError, or a message from
            library internals (std::vector, std::bad_alloc, pybind11 casts)
  garbage   the call returned an output the inputs make invalid (target-specific check)
  crash     the worker died (a signal, e.g. SIGSEGV / SIGABRT, or an exit status)
  hang      no answer within the time limit (the worker is killed)
  harness   the generator or the garbage check itself failed (a bug here, not in the target)
Workers are restarted after a crash or a hang; the cases queued behind it run in a new worker.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib.util
import json
import os
import re
import resource
import selectors
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import zlib
from collections import deque
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import IO, Any

import numpy as np

OUTCOMES = ("ok", "error", "unclear", "garbage", "crash", "hang", "harness")
FAILING = ("crash", "hang", "garbage", "harness")
# Messages that come from library internals, not from a check of ours.
INTERNAL_MESSAGES = (
    "vector::",
    "max_size()",
    "bad_alloc",
    "basic_string",
    "_M_",
    "Unable to cast",
    "Unable to convert",
    "std::",
)


# The first line of a report a dying process leaves on stderr.
REPORT_START = re.compile(
    r"ERROR: (Address|Leak)Sanitizer|runtime error: |terminate called|Assertion .* failed"
    r"|Fatal Python error|Segmentation fault"
)


class TargetCrashed(Exception):  # noqa: N818 (a report, not an error of the caller)
    """Raised by a call whose helper process (e.g. a C++ driver) died: counted as a crash."""


class HarnessError(Exception):
    """Raised by a call that could not even pose its case (a bug here): counted as harness."""


def _no_garbage(args: dict[str, Any], result: Any) -> str | None:
    return None


@dataclasses.dataclass(frozen=True)
class Target:
    """One entry point: `generate` makes plain arguments (numbers, strings, numpy arrays, dicts)
    from a numpy Generator, `call` runs the entry point on them, `garbage` returns why an output
    is invalid for those arguments (None if it is fine)."""

    name: str
    generate: Callable[[np.random.Generator], dict[str, Any]]
    call: Callable[[dict[str, Any]], Any]
    garbage: Callable[[dict[str, Any], Any], str | None] = _no_garbage
    covers: tuple[str, ...] = ()  # the names of the API this target exercises


def case_rng(seed: int, target: str, index: int) -> np.random.Generator:
    """The generator of one case: independent of every other case and of the worker."""
    return np.random.default_rng([seed, zlib.crc32(target.encode()), index])


def classify_exception(error: BaseException) -> tuple[str, str]:
    """(outcome, detail) for an exception raised by a call."""
    message = str(error).strip()
    detail = f"{type(error).__name__}: {message}" if message else type(error).__name__
    if isinstance(error, TargetCrashed):
        return "crash", message
    if isinstance(error, HarnessError):
        return "harness", message
    if isinstance(error, ValueError | TypeError | IndexError) and message:
        if any(marker in message for marker in INTERNAL_MESSAGES):
            return "unclear", detail
        return "error", detail
    return "unclear", detail


def run_case(target: Target, seed: int, index: int) -> tuple[str, str]:
    """Runs one case in this process: (outcome, detail) for every outcome but crash and hang."""
    try:
        args = target.generate(case_rng(seed, target.name, index))
    except Exception:  # noqa: BLE001 (a generator bug is reported, never hidden)
        return "harness", "generator failed: " + traceback.format_exc(limit=3)
    try:
        result = target.call(args)
    except Exception as error:  # noqa: BLE001 (classifying exceptions is the point)
        return classify_exception(error)
    try:
        why = target.garbage(args, result)
    except Exception:  # noqa: BLE001
        return "harness", "garbage check failed: " + traceback.format_exc(limit=3)
    return ("garbage", why) if why else ("ok", "")


def load_targets(spec: str) -> list[Target]:
    """Targets from "path/to/module.py:function" (the function returns a list of Target)."""
    path, _, function = spec.rpartition(":")
    module_name = "fuzz_targets_" + str(abs(hash(path)))
    loader_spec = importlib.util.spec_from_file_location(module_name, path)
    if loader_spec is None or loader_spec.loader is None:
        raise ImportError(f"cannot load targets from {path}")
    module = importlib.util.module_from_spec(loader_spec)
    sys.modules[module_name] = module
    loader_spec.loader.exec_module(module)
    return list(getattr(module, function)())


def worker_main(spec: str, seed: int) -> int:
    """Worker loop: one JSON task per stdin line ({"target", "index"}), one JSON answer per line
    ({"index", "outcome", "detail"}). The parent reads the answer before the next task's."""
    targets = {t.name: t for t in load_targets(spec)}
    out = sys.stdout
    for line in sys.stdin:
        task = json.loads(line)
        outcome, detail = run_case(targets[task["target"]], seed, task["index"])
        out.write(json.dumps({"index": task["index"], "outcome": outcome, "detail": detail[:2000]}))
        out.write("\n")
        out.flush()
    return 0


def _under_asan(env: dict[str, str]) -> bool:
    return "libasan" in env.get("LD_PRELOAD", "")


def _limit_memory(memory_mb: int, address_space: bool) -> Callable[[], None]:
    def apply() -> None:
        os.setsid()  # own process group: a hang's kill takes the worker's helpers with it
        if memory_mb > 0 and address_space:
            limit = memory_mb * 1024 * 1024
            resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))  # no core files per crash

    return apply


@dataclasses.dataclass
class CaseResult:
    target: str
    index: int
    outcome: str
    detail: str


class Worker:
    """One worker subprocess and the cases sent to it, in order."""

    def __init__(self, spec: str, seed: int, memory_mb: int, env: dict[str, str] | None) -> None:
        self.stderr: IO[bytes] = tempfile.TemporaryFile()
        env = dict(os.environ if env is None else env)
        asan = _under_asan(env)
        if asan and memory_mb > 0:
            # ASan reserves terabytes of address space: limit the resident size instead.
            options = env.get("ASAN_OPTIONS", "")
            env["ASAN_OPTIONS"] = f"{options}:hard_rss_limit_mb={memory_mb}".lstrip(":")
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).resolve()), "--worker", spec, "--seed", str(seed)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.stderr,
            preexec_fn=_limit_memory(memory_mb, address_space=not asan),  # noqa: PLW1509 (no threads in the parent)
            env=env,
        )
        assert self.proc.stdin is not None and self.proc.stdout is not None
        self.stdin = self.proc.stdin
        self.stdout = self.proc.stdout
        self.pending: deque[tuple[str, int]] = deque()
        self.buffer = b""
        self.deadline = 0.0

    def send(self, target: str, index: int, timeout_s: float) -> None:
        if not self.pending:
            self.deadline = time.monotonic() + timeout_s
        self.pending.append((target, index))
        try:
            self.stdin.write((json.dumps({"target": target, "index": index}) + "\n").encode())
            self.stdin.flush()
        except BrokenPipeError:
            pass  # it died on an earlier case: its EOF assigns the crash, the rest is re-queued

    def stderr_tail(self, lines: int = 25) -> str:
        """The last report in the worker's stderr (a sanitizer report, an uncaught exception)
        from its first line, else its last lines."""
        self.stderr.seek(0)
        text = self.stderr.read().decode(errors="replace").splitlines()
        starts = [i for i, line in enumerate(text) if REPORT_START.search(line)]
        if starts:
            return "\n".join(text[starts[-1] : starts[-1] + lines])
        return "\n".join(text[-lines:])

    def kill(self) -> None:
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.proc.wait()
        for stream in (self.stdin, self.stdout):
            try:
                stream.close()
            except OSError:
                pass
        self.stderr.close()


def _death_reason(returncode: int | None) -> str:
    if returncode is not None and returncode < 0:
        try:
            return f"killed by {signal.Signals(-returncode).name}"
        except ValueError:
            return f"killed by signal {-returncode}"
    return f"exited with status {returncode}"


def run_campaign(
    spec: str,
    tasks: Iterable[tuple[str, int]],
    seed: int,
    workers: int = 2,
    timeout_s: float = 10.0,
    memory_mb: int = 2048,
    batch: int = 16,
    env: dict[str, str] | None = None,
    progress: Callable[[int], None] | None = None,
) -> list[CaseResult]:
    """Runs every (target, index) task in `workers` worker processes; returns one result each.

    Each worker holds up to `batch` cases; the time limit is per case (from the moment the case
    before it answered). A worker that dies or goes quiet is replaced; its first pending case
    gets the crash or hang, the others are queued again."""
    queue: deque[tuple[str, int]] = deque(tasks)
    results: list[CaseResult] = []
    selector = selectors.DefaultSelector()
    pool: list[Worker] = []

    def start() -> None:
        worker = Worker(spec, seed, memory_mb, env)
        pool.append(worker)
        selector.register(worker.stdout, selectors.EVENT_READ, worker)

    def retire(worker: Worker, outcome: str, detail: str) -> None:
        target, index = worker.pending.popleft()
        results.append(CaseResult(target, index, outcome, detail))
        queue.extendleft(reversed(worker.pending))
        worker.pending.clear()
        selector.unregister(worker.stdout)
        pool.remove(worker)
        worker.kill()

    def feed(worker: Worker) -> None:
        while queue and len(worker.pending) < batch:
            target, index = queue.popleft()
            worker.send(target, index, timeout_s)

    try:
        while queue or any(w.pending for w in pool):
            while len(pool) < workers and queue:
                start()
            for worker in pool:
                feed(worker)
            now = time.monotonic()
            wait = min((w.deadline for w in pool if w.pending), default=now + 1.0) - now
            for key, _ in selector.select(timeout=max(0.0, min(wait, 1.0))):
                worker = key.data
                chunk = os.read(worker.stdout.fileno(), 1 << 16)
                if not chunk:  # EOF: the worker died with a case pending
                    worker.proc.wait()
                    detail = _death_reason(worker.proc.returncode)
                    tail = worker.stderr_tail()
                    retire(worker, "crash", detail + ("\n" + tail if tail else ""))
                    continue
                worker.buffer += chunk
                while b"\n" in worker.buffer:
                    line, worker.buffer = worker.buffer.split(b"\n", 1)
                    answer = json.loads(line)
                    target, index = worker.pending.popleft()
                    assert index == answer["index"]
                    results.append(CaseResult(target, index, answer["outcome"], answer["detail"]))
                    if progress is not None:
                        progress(len(results))
                    worker.deadline = time.monotonic() + timeout_s
            now = time.monotonic()
            for worker in list(pool):
                if worker.pending and now > worker.deadline:
                    retire(worker, "hang", f"no answer within {timeout_s:g} s")
    finally:
        for worker in list(pool):
            worker.kill()
        selector.close()
    return results


def tally(results: Iterable[CaseResult]) -> dict[str, dict[str, int]]:
    """Per target: cases and the count of each outcome."""
    table: dict[str, dict[str, int]] = {}
    for r in results:
        row = table.setdefault(r.target, {"cases": 0, **{o: 0 for o in OUTCOMES}})
        row["cases"] += 1
        row[r.outcome] += 1
    return table


def format_table(table: dict[str, dict[str, int]]) -> str:
    columns = ("cases", *OUTCOMES)
    width = max([len("entry point"), *(len(name) for name in table)])
    lines = [f"{'entry point':<{width}} " + " ".join(f"{c:>7}" for c in columns)]
    for name in sorted(table):
        lines.append(f"{name:<{width}} " + " ".join(f"{table[name][c]:>7}" for c in columns))
    return "\n".join(lines)


def closing_line(table: dict[str, dict[str, int]]) -> str:
    total = {c: sum(row[c] for row in table.values()) for c in ("cases", *OUTCOMES)}
    line = (
        f"fuzz: {total['cases']} cases, {total['crash']} crashes, {total['hang']} hangs, "
        f"{total['garbage']} garbage ({total['ok']} ok, {total['error']} clean errors, "
        f"{total['unclear']} unclear errors"
    )
    if total["harness"]:
        line += f", {total['harness']} HARNESS ERRORS"
    return line + ")"


def worker_entry(argv: list[str]) -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("--worker", required=True)
    parser.add_argument("--seed", type=int, required=True)
    args = parser.parse_args(argv)
    return worker_main(args.worker, args.seed)


if __name__ == "__main__":
    # Run as the module fuzz_harness, not as __main__: the targets import fuzz_harness, and
    # their TargetCrashed / HarnessError must be the classes classify_exception() knows.
    import fuzz_harness

    sys.exit(fuzz_harness.worker_entry(sys.argv[1:]))
