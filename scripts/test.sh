#!/usr/bin/env bash
# Every test: install what is missing, build plain and sanitized, and run the
# whole suite in both builds (the sanitized one under ASan + UBSan), then
# fuzz each input surface for 12 s (scripts/fuzz.sh). Each stage runs even
# if one before it failed (a test stage only if its build succeeded); a
# table of the stages and their results follows, then ctest's own summary
# lines of both suites. Exit status 1 if any stage failed.
set -uo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc 2>/dev/null || echo 2)
stages=()
results=()

# stage NAME COMMAND...: runs COMMAND and records whether it passed.
stage() {
  local name=$1
  shift
  echo "== $name =="
  if "$@"; then
    results+=(passed)
  else
    results+=(FAILED)
  fi
  stages+=("$name")
}

# skip NAME WHY: records a stage that could not run as failed.
skip() {
  echo "== $1 == not run: $2"
  stages+=("$1")
  results+=("FAILED (not run: $2)")
}

# suite DIR: the whole ctest suite of a build, its output also in
# DIR/ctest.log.
suite() {
  # deps.sh installs OpenMPI: test_cluster fails, not skips, without it
  BSIM_REQUIRE_MPI=1 ctest --test-dir "$1" --output-on-failure -j "$jobs" 2>&1 | tee "$1/ctest.log"
}

suite_sanitized() {
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    suite build-asan
}

rm -f build/ctest.log build-asan/ctest.log

stage "dependencies" scripts/deps.sh
stage "build (Release)" scripts/build.sh
release_built=${results[-1]}
stage "build (ASan + UBSan)" scripts/build.sh --sanitize
asan_built=${results[-1]}
if [ "$release_built" = passed ]; then
  stage "tests (Release)" suite build
else
  skip "tests (Release)" "its build failed"
fi
if [ "$asan_built" = passed ]; then
  stage "tests (ASan + UBSan)" suite_sanitized
else
  skip "tests (ASan + UBSan)" "its build failed"
fi
stage "fuzzing (libFuzzer, ASan + UBSan, about two minutes)" scripts/fuzz.sh 12

status=0
echo
echo "== summary =="
printf '%-52s %s\n' "stage" "result"
for i in "${!stages[@]}"; do
  printf '%-52s %s\n' "${stages[$i]}" "${results[$i]}"
  [ "${results[$i]}" = passed ] || status=1
done
# ctest's own last lines (the tests that failed, the times) close the output.
for log in build-asan/ctest.log build/ctest.log; do
  if [ -f "$log" ]; then
    echo
    echo "== ctest: $log =="
    sed -n '/% tests passed/,$p' "$log"
  fi
done
exit $status
