#!/usr/bin/env bash
# A bounded fuzzing run: builds the libFuzzer targets of tests/fuzz with
# clang (ASan + UBSan) in build-fuzz/ and runs each for SECONDS seconds
# (default 20, so about a minute in all) from the seed corpus and every
# input that once failed (tests/fuzz/regressions). The corpus grows in
# build-fuzz/corpus/, never in the tree. An input that crashes, hangs
# (10 s) or exhausts memory (2 GB) fails the run: it is saved in
# build-fuzz/findings/ and, once fixed, belongs in tests/fuzz/regressions/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-20}
jobs=$(nproc 2>/dev/null || echo 2)
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBSIM_FUZZ=ON >/dev/null
cmake --build build-fuzz -j "$jobs" --target fuzz_scene fuzz_experiment fuzz_set >/dev/null
mkdir -p build-fuzz/findings
status=0
for t in scene experiment set; do
  corpus=build-fuzz/corpus/$t
  mkdir -p "$corpus"
  cp -n tests/fuzz/corpus/$t/* tests/fuzz/regressions/$t/* "$corpus"/ 2>/dev/null || true
  log=build-fuzz/fuzz_$t.log
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    build-fuzz/tests/fuzz/fuzz_$t "$corpus" -dict=tests/fuzz/yaml.dict \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="build-fuzz/findings/$t-" >"$log" 2>&1; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    echo "fuzz_$t: ${runs:-?} inputs in ${seconds} s, no finding"
  else
    status=1
    echo "fuzz_$t: FOUND a failing input (log: $log):" >&2
    grep -E "ERROR|SUMMARY|Test unit written" "$log" >&2 || tail -n 20 "$log" >&2
  fi
done
exit $status
