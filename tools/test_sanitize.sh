#!/usr/bin/env bash
# ASan + UBSan: builds the core library, the gtests and the Python module in their own catkin
# workspace (.ws-san, so .ws keeps its Release build), then runs every gtest and every pytest
# with the sanitizer runtime. Prints one closing line "sanitize: N passed, M failed" and exits
# non-zero on any failed test, missing result or sanitizer report. rostests are not run here.
# With --build-only it only builds (for tools/fuzz_sanitize.sh).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
SAN_WS="$REPO/.ws-san"
SAN_FLAGS="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
RESULTS="$SAN_WS/results"
# Only the targets the tests need (the nodelets and rostests are not built: 2 cores in CI);
# gencfg gives the pytests the dynamic_reconfigure Python modules. pybind11 adds no LTO in the
# RelWithDebInfo configuration.
# shellcheck disable=SC2046 # pybind11_cmake_args: one argument or none
build_instrumented "$SAN_WS" "$SAN_FLAGS" sanitize $(pybind11_cmake_args) \
  downstream_perception_core test_core _core downstream_perception_gencfg || exit 1
cd "$SAN_WS"
[[ "${1:-}" == "--build-only" ]] && exit 0 # tools/fuzz_sanitize.sh

rm -rf "$RESULTS"
mkdir -p "$RESULTS"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
status=0

# gtests: leaks in our own C++ are real, so LeakSanitizer stays on. Two processes side by side,
# one per core, split by a filter and its negation (together every test, each once): the
# TsdfConfirm suite (about 270 s instrumented, 2026-12-07) and the rest (about 290 s). gtest's
# own round-robin sharding put both table-top tests in one shard: 113 against 444 s.
filters=('TsdfConfirm.*' '-TsdfConfirm.*')
pids=()
for i in "${!filters[@]}"; do
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1" ./devel/lib/downstream_perception/test_core \
    --gtest_filter="${filters[$i]}" --gtest_output="xml:$RESULTS/gtest-test_core-$i.xml" \
    > "$RESULTS/gtest-$i.log" 2>&1 &
  pids+=($!)
done
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
grep -E '^\[  (PASSED|FAILED) ' "$RESULTS"/gtest-*.log || true

# pytests: Python is not instrumented, so the runtime is preloaded; CPython leaks by design.
source_workspace_at() {
  set +u
  # shellcheck disable=SC1091
  source "$1/devel/setup.bash"
  set -u
}
source_workspace_at "$SAN_WS"
python=/usr/bin/python3
[[ -x "$WS/py-venv/bin/python" ]] && python="$WS/py-venv/bin/python" # motmetrics (make deps)
preload="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1"
module="$(LD_PRELOAD="$preload" "$python" -c \
  'import downstream_perception._core as c; print(c.__file__)' 2> "$RESULTS/import.log")" || {
  cat "$RESULTS/import.log"
  echo "sanitize: 0 passed, 1 failed (the sanitized module does not import)"
  exit 1
}
# The symbol list into a variable first: `nm | grep -q` under pipefail fails when grep stops
# reading early (nm gets SIGPIPE).
symbols="$(nm -D "$module" 2>/dev/null || true)"
if [[ "$module" != "$SAN_WS/devel/"* ]] || ! grep -q __asan_init <<< "$symbols"; then
  echo "sanitize: 0 passed, 1 failed (python imports $module, not the sanitized module)"
  exit 1
fi
echo "sanitize: python imports $module (instrumented)"
# Two workers when pytest-xdist is there (tools/python_venv.sh): one per core.
workers=()
"$python" -c "import xdist" 2> /dev/null && workers=(-n 2)
# pytest captures each test's stderr in a file of its own, lost when a sanitizer aborts the
# process (the test still fails: the worker crashes); so reports go to files (one per process, the
# pid appended) and are added to pytest.log, where they count.
reports="$RESULTS/pytest-sanitizer"
(cd "$REPO" && DP_PARTIAL_BUILD=1 LD_PRELOAD="$preload" ASAN_OPTIONS="$ASAN_OPTIONS:log_path=$reports" \
  UBSAN_OPTIONS="$UBSAN_OPTIONS:log_path=$reports" "$python" -m pytest -q -p no:cacheprovider \
  "${workers[@]}" test/pytest --junitxml="$RESULTS/pytest.xml") > "$RESULTS/pytest.log" 2>&1 || status=1
tail -1 "$RESULTS/pytest.log"
for report in "$reports".*; do
  if [[ -f "$report" ]]; then cat "$report" >> "$RESULTS/pytest.log"; fi
done

summary_status=0
python3 "$REPO/tools/test_summary.py" "$RESULTS" --label sanitize \
  --expect gtest-test_core-0.xml --expect gtest-test_core-1.xml --expect pytest.xml \
  --sanitizer-log "$RESULTS/gtest-0.log" --sanitizer-log "$RESULTS/gtest-1.log" \
  --sanitizer-log "$RESULTS/pytest.log" || summary_status=$?
if ((status != 0 && summary_status == 0)); then
  echo "sanitize: a test process failed without a failing test case (see $RESULTS/*.log)"
  summary_status=1
fi
exit "$summary_status"
