#!/usr/bin/env bash
# ThreadSanitizer: builds the core library and the gtests in their own catkin workspace
# (.ws-tsan) and runs the gtests of the code that shares work between threads (the two-thread
# scan walk, inflation bands and stamping, the TSDF's octree worker, runShared itself), each
# several times so the helper thread really runs beside the caller. ASan cannot see a data race
# whose two accesses do not overlap in time; a race in the scan walk's bands showed up only once
# in ~400 loaded runs (a wrong cell, no crash), which TSan reports on the first run that has both
# threads working. Prints "tsan: N passed, M failed" and exits non-zero on a failed test or a
# TSan report.
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
TSAN_WS="$REPO/.ws-tsan"
TSAN_FLAGS="-fsanitize=thread -fno-omit-frame-pointer"
RESULTS="$TSAN_WS/results"
build_instrumented "$TSAN_WS" "$TSAN_FLAGS" tsan downstream_perception_core test_core || exit 1
cd "$TSAN_WS"
rm -rf "$RESULTS"
mkdir -p "$RESULTS"
# halt_on_error: a report fails the run even where the test's own comparisons happen to pass.
export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1"
status=0
./devel/lib/downstream_perception/test_core --gtest_filter="$(cat "$REPO/test/tsan_filter.txt")" \
  --gtest_repeat=3 --gtest_output="xml:$RESULTS/gtest-test_core.xml" > "$RESULTS/gtest.log" 2>&1 ||
  status=1
grep -E '^\[  (PASSED|FAILED) ' "$RESULTS/gtest.log" | sort | uniq -c || true
summary_status=0
python3 "$REPO/tools/test_summary.py" "$RESULTS" --label tsan --expect gtest-test_core.xml \
  --sanitizer-log "$RESULTS/gtest.log" || summary_status=$?
if ((status != 0 && summary_status == 0)); then
  grep -m1 -A30 'WARNING: ThreadSanitizer' "$RESULTS/gtest.log" || tail -30 "$RESULTS/gtest.log"
  echo "tsan: the test process failed without a failing test case (see $RESULTS/gtest.log)"
  summary_status=1
fi
exit "$summary_status"
