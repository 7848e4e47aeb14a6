#!/usr/bin/env bash
# A bounded fuzzing run: builds the libFuzzer targets of tests/fuzz with
# clang (ASan + UBSan) in build-fuzz/ and runs each for SECONDS seconds
# (default 12: about two minutes for the eight targets) from the seed
# corpus and every input that once failed (tests/fuzz/regressions), with
# the target's dictionary. Targets may be named after SECONDS to run only
# those. The corpus grows in build-fuzz/corpus/, never in the tree. An
# input that crashes, hangs (10 s) or exhausts memory (2 GB) fails the
# run: it is saved in build-fuzz/findings/ and, once fixed, belongs in
# tests/fuzz/regressions/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-12}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(scene experiment set stiffness markov stored journal options)
fi
jobs=$(nproc 2>/dev/null || echo 2)
# The targets write their inputs and directories to files: in memory when
# /dev/shm is there (syncs cost nothing), several times faster.
if [ -z "${TMPDIR:-}" ] && [ -d /dev/shm ] && [ -w /dev/shm ]; then
  export TMPDIR=/dev/shm
fi
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DBSIM_FUZZ=ON >/dev/null
cmake --build build-fuzz -j "$jobs" --target "${targets[@]/#/fuzz_}" >/dev/null
mkdir -p build-fuzz/findings
status=0
for t in "${targets[@]}"; do
  # The target's dictionary; the options target's usage errors stay off
  # the log (libFuzzer keeps its own and the sanitizers' reports).
  extra=()
  case $t in
    scene | experiment | set) extra=(-dict=tests/fuzz/yaml.dict) ;;
    stiffness) extra=(-dict=tests/fuzz/csv.dict) ;;
    markov | stored) extra=(-dict=tests/fuzz/stored.dict) ;;
    options) extra=(-dict=tests/fuzz/options.dict -close_fd_mask=2) ;;
  esac
  corpus=build-fuzz/corpus/$t
  mkdir -p "$corpus"
  cp -n tests/fuzz/corpus/$t/* "$corpus"/ 2>/dev/null || true
  cp -n tests/fuzz/regressions/$t/* "$corpus"/ 2>/dev/null || true
  log=build-fuzz/fuzz_$t.log
  if ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    build-fuzz/tests/fuzz/fuzz_$t "$corpus" "${extra[@]}" \
      -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
      -artifact_prefix="build-fuzz/findings/$t-" >"$log" 2>&1; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
    echo "fuzz_$t: ${runs:-?} inputs in ${seconds} s, no finding"
  else
    status=1
    echo "fuzz_$t: FOUND a failing input (log: $log):" >&2
    grep -E "ERROR|SUMMARY|Test unit written|fuzz:" "$log" >&2 || tail -n 20 "$log" >&2
  fi
done
exit $status
