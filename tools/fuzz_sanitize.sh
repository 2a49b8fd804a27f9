#!/usr/bin/env bash
# make fuzz-sanitize: the fuzz campaign over the binding entry points (not the message checks:
# their driver is not built in .ws-san) against the ASan+UBSan module of make test-sanitize, so
# that out-of-bounds accesses and undefined behaviour show up as crashes even where the Release
# build happens to survive them. Not part of CI (about three times slower than make fuzz).
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/env.sh"
"$REPO/tools/test_sanitize.sh" --build-only
set +u
# shellcheck disable=SC1091
source "$REPO/.ws-san/devel/setup.bash"
set -u
cd "$REPO"
LD_PRELOAD="$(gcc -print-file-name=libasan.so):$(gcc -print-file-name=libubsan.so)" \
  ASAN_OPTIONS="detect_leaks=0:abort_on_error=1" UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  python3 test/fuzz/fuzz.py --skip msg --timeout 30 --out out/fuzz-sanitize "$@"
