#!/usr/bin/env bash
# How far each backend's body strays from the thesis backend's at a step of
# 5e-5 s (the reference) on the essay's gate (configs/thesis/gate.yaml: 7 N,
# random force 20 N, 12 s): the largest distance between the two body
# centres over the trial, sampled every 4 ms, for each backend at each step.
#
#   scripts/gate_error.sh [--trials N] [--backends LIST] [--dts LIST] [--seed S]
#                         [--set KEY=VALUE]...
#
# LIST of backends: comma-separated, each NAME or NAME:KEY=VALUE:... (default
# thesis,box2d,chipmunk); LIST of steps: comma-separated seconds, each
# dividing 0.004 (default 0.004,0.001,0.0005,0.00025). Trials 0..N-1 of
# group 0 of seed S (default 3 trials, seed 1); --set applies to every run.
# Where a trial ends (side exit, traversal) before the reference, the
# distance is taken over the steps both ran. Prints one line per backend
# and step: the distance of each trial (m) and the largest.
set -euo pipefail
cd "$(dirname "$0")/.."
exe=build/beamsim
[ -x "$exe" ] || { echo "build first (scripts/build.sh)" >&2; exit 2; }
trials=3 seed=1 backends=thesis,box2d,chipmunk dts=0.004,0.001,0.0005,0.00025
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --trials) trials=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --backends) backends=$2; shift 2 ;;
    --dts) dts=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    *) echo "scripts/gate_error.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
scene=configs/thesis/gate.yaml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# run OUT DT STRIDE TRIAL BACKEND-ARGS...: the trajectory every STRIDE steps
run() {
  local out=$1 dt=$2 stride=$3 trial=$4
  shift 4
  "$exe" run "$scene" "$@" "${sets[@]}" --set integration.dt="$dt" --seed "$seed" \
    --trial "$trial" --stride "$stride" --trajectory "$out" >/dev/null 2>&1 || {
    local rc=$?
    # 1: an unstable trial, whose trajectory is still written; else a failure
    [ $rc -eq 1 ] || { echo "beamsim run $* --set integration.dt=$dt failed ($rc)" >&2; exit 1; }
  }
}
for ((t = 0; t < trials; t++)); do
  run "$tmp/ref_$t.csv" 0.00005 80 "$t"
done
IFS=, read -r -a blist <<< "$backends"
IFS=, read -r -a dlist <<< "$dts"
for b in "${blist[@]}"; do
  name=${b%%:*}
  args=(--backend "$name")
  if [ "$b" != "$name" ]; then
    IFS=: read -r -a kvs <<< "${b#*:}"
    for kv in "${kvs[@]}"; do args+=(--backend-opt "$kv"); done
  fi
  for dt in "${dlist[@]}"; do
    stride=$(python3 -c "print(round(0.004 / $dt))")
    line="$b dt $dt:"
    for ((t = 0; t < trials; t++)); do
      run "$tmp/b_$t.csv" "$dt" "$stride" "$t" "${args[@]}"
      line+=" $(python3 - "$tmp/ref_$t.csv" "$tmp/b_$t.csv" <<'EOF'
import csv, math, sys
ref = list(csv.reader(open(sys.argv[1])))[1:]
run = list(csv.reader(open(sys.argv[2])))[1:]
print("%.4g" % max(math.hypot(float(a[1]) - float(b[1]), float(a[2]) - float(b[2]))
                   for a, b in zip(ref, run)))
EOF
)"
    done
    echo "$line" | awk '{m = 0; for (i = 4; i <= NF; i++) if ($i + 0 > m) m = $i + 0;
      printf "%s  largest %.4g m\n", $0, m}'
  done
done
