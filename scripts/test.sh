#!/usr/bin/env bash
# Every test: install what is missing, build plain and sanitized, and run the
# whole suite in both builds (the sanitized one under ASan + UBSan), then
# fuzz each input parser for 20 s (scripts/fuzz.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh --sanitize
jobs=$(nproc 2>/dev/null || echo 2)
echo "== tests (Release) =="
ctest --test-dir build --output-on-failure -j "$jobs"
echo "== tests (ASan + UBSan) =="
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
echo "== fuzzing (libFuzzer, ASan + UBSan, about a minute) =="
scripts/fuzz.sh 20
