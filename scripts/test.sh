#!/usr/bin/env bash
# scripts/test.sh — sets everything up (apt packages, Node test tools,
# Chromium), builds in Release and runs the whole test suite, then builds the
# library and its unit and property tests again with AddressSanitizer and
# UndefinedBehaviorSanitizer (-O1, build-asan/) and runs them. CI runs
# exactly this. VOXPRESS_NO_SANITIZE=1 skips the second part (local use).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/setup.sh" --tests
cd "$root/build"
ctest --output-on-failure -j "$(nproc)"
[ "${VOXPRESS_NO_SANITIZE:-0}" = 1 ] && exit 0

echo "== the unit and property tests under ASan + UBSan" >&2
suites=(core_tests extract_tests io_tests eval_tests smooth_tests voxart_tests render_tests)
cmake -S "$root" -B "$root/build-asan" -G Ninja -DCMAKE_BUILD_TYPE=Sanitize -DCMAKE_CXX_FLAGS_SANITIZE="-O1 -g0" \
  -DCMAKE_C_FLAGS_SANITIZE="-O1 -g0" -DVOXPRESS_SANITIZE=ON -DVOXPRESS_PYTHON=OFF -DVOXPRESS_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-asan" -j "$(nproc)" --target "${suites[@]}" >&2
# Each suite's executable directly (the CLI, Python and browser tests ran in
# Release above), two at a time; any sanitizer report fails the suite.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
printf '%s\n' "${suites[@]}" | xargs -P "$(nproc)" -I{} sh -c \
  '"$0"/build-asan/tests/{} --gtest_brief=1 > "$0"/build-asan/{}.log 2>&1 && echo "sanitized {}: passed" ||
   { echo "sanitized {}: FAILED"; tail -40 "$0"/build-asan/{}.log; exit 1; }' "$root"
