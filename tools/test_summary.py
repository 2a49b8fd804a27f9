#!/usr/bin/env python3
"""Prints one line counting the test cases in JUnit XML results.

catkin_test_results counts every gtest case twice, so the closing line is counted here.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET
from pathlib import Path


def main(results_dir: str) -> int:
    passed = failed = skipped = 0
    files = sorted(Path(results_dir).rglob("*.xml"))
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
    if not files or passed + failed == 0:
        print("tests: 0 passed, 1 failed (no test results found)")
        return 1
    print(f"tests: {passed} passed, {failed} failed, {skipped} skipped ({len(files)} result files)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
