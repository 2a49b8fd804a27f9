#!/usr/bin/env bash
# Runs every test (gtest, rostest, pytest) through catkin and prints one closing summary line.
# Exits non-zero if any test failed or produced no result.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
cd "$WS"
rm -rf build/test_results
catkin_make -j2 tests > "$WS/tests_build.log" 2>&1 || { tail -50 "$WS/tests_build.log"; exit 1; }
# run_tests always exits 0 by catkin's design; catkin_test_results carries the verdict.
catkin_make -j1 run_tests 2>&1 | tee "$WS/run_tests.log" | grep -E '^(\[ *(FAILED|PASSED) *\]|.*(passed|failed|error).* in [0-9.]+s|\[ROSTEST\]|\[Testcase|FAILURE|ERROR)' || true
set +e
summary="$(catkin_test_results build/test_results --all 2>&1)"
status=$?
set -e
# catkin_test_results counts gtest cases twice; show its detail only when something failed.
if [[ "$status" != 0 ]]; then echo "$summary"; fi
count_status=0
python3 "$REPO/tools/test_summary.py" build/test_results || count_status=$?
if [[ "$status" == 0 ]]; then status=$count_status; fi
exit "$status"
