#!/usr/bin/env python3
"""Prints one line counting the test cases in JUnit XML results.

catkin_test_results counts every gtest case twice, so the closing line is counted here.
make test-sanitize also names the result files it expects (a process killed by a sanitizer
writes none) and the logs in which any sanitizer report counts as a failure.
"""

from __future__ import annotations

import argparse
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

# The first line of every ASan / LSan / UBSan / TSan report.
SANITIZER_REPORT = re.compile(
    r"ERROR: (Address|Leak)Sanitizer|WARNING: ThreadSanitizer|runtime error: "
    r"|SUMMARY: UndefinedBehaviorSanitizer"
)


def sanitizer_reports(log: Path) -> list[str]:
    """The report lines in a log (none if the log does not exist)."""
    if not log.is_file():
        return []
    text = log.read_text(errors="replace")
    return [line for line in text.splitlines() if SANITIZER_REPORT.search(line)]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("results_dir", nargs="?", default=".")
    parser.add_argument("--label", default="tests", help="first word of the closing line")
    parser.add_argument(
        "--expect", action="append", default=[], help="a result file that must exist"
    )
    parser.add_argument("--sanitizer-log", action="append", default=[], type=Path)
    args = parser.parse_args(argv)
    results_dir = Path(args.results_dir)
    passed = failed = skipped = 0
    files = sorted(results_dir.rglob("*.xml"))
    for path in files:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError:
            print(f"unreadable result file: {path}")
            failed += 1
            continue
        for case in root.iter("testcase"):
            if case.find("failure") is not None or case.find("error") is not None:
                failed += 1
                print(f"FAILED: {path.name}: {case.get('classname')}.{case.get('name')}")
            elif case.find("skipped") is not None:
                skipped += 1
            else:
                passed += 1
    for name in args.expect:
        if not (results_dir / name).is_file():
            print(f"FAILED: no {name} (the test process died before writing it)")
            failed += 1
    reports = 0
    for log in args.sanitizer_log:
        lines = sanitizer_reports(log)
        for line in lines[:5]:
            print(f"SANITIZER: {log.name}: {line.strip()}")
        reports += len(lines)
    if not files or passed + failed == 0:
        print(f"{args.label}: 0 passed, 1 failed (no test results found)")
        return 1
    extra = f", {reports} sanitizer report line(s)" if reports else ""
    print(
        f"{args.label}: {passed} passed, {failed + (1 if reports else 0)} failed, "
        f"{skipped} skipped ({len(files)} result files{extra})"
    )
    return 1 if failed or reports else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
