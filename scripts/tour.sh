#!/usr/bin/env bash
# The README's tour, timed: runs each of its commands in order (after
# scripts/build.sh, which builds what is not built yet) and prints how long
# each took on this machine, so that the README's times can be measured
# again anywhere. Outputs go to out/tour/ instead of out/, which the tour
# removes first (its markov build would otherwise reuse the maps of an
# earlier tour, and every other command refuse the finished results there).
# Usage: scripts/tour.sh [--quick]   (--quick: the essay comparison at 100
# trials a group instead of 1000)
set -euo pipefail
cd "$(dirname "$0")/.."
essay_trials=1000
[ "${1:-}" = "--quick" ] && essay_trials=100
b=build/beamsim
o=out/tour
[ -e "$o" ] && echo "scripts/tour.sh: removing $o (an earlier tour's outputs)" >&2
rm -rf "$o"
mkdir -p "$o"
printf '%-8s %s\n' "seconds" "command"
step() {
  local t0 t1
  t0=$(date +%s.%N)
  "$@" >"$o/last.log" 2>&1 || {
    st=$?
    # compare and regress exit 3 on a disagreement beyond the rule: a finding
    [ "$st" -eq 3 ] || { echo "failed ($st): $*" >&2; cat "$o/last.log" >&2; exit 1; }
  }
  t1=$(date +%s.%N)
  awk -v a="$t0" -v b="$t1" -v c="${*#$b }" 'BEGIN { printf "%-8.1f %s\n", b - a, c }'
}
t0=$(date +%s.%N)
step scripts/build.sh
step $b run configs/thesis/gate.yaml --seed 3 --trial 2 --out $o/run
step $b plot $o/run
step $b sweep configs/thesis/h2_asymmetric.yaml --out $o/h2
step $b plot $o/h2
step $b sweep configs/thesis/h2_asymmetric.yaml --grid beams.0.stiffness=200,400 --set body.mass=2 --out $o/h2-heavy
step $b run $o/h2 --group 10 --trial 3 --out $o/g10t3
step $b video $o/h2 --group 10 --trial 3 --out $o/g10t3.mp4
step $b compare configs/thesis/h1_symmetric.yaml --out $o/h1-compare
step $b regress $o/h1-compare --out $o/h1-rerun
step $b landscape configs/thesis/gate.yaml --out $o/landscape
step $b escape $o/h2 --out $o/escape
step $b sweep configs/lattice/c_track_1000.yaml --out $o/c-track
step $b markov build configs/markov/c_track.yaml --bins 4,4,3 --trials 800 --entries flow:1 --out $o/markov-maps
step $b markov predict configs/lattice/c_track.yaml --map $o/markov-maps --out $o/c-track-predicted
step $b markov validate configs/markov/c_track.yaml --map $o/markov-maps --out $o/markov-check
step $b video configs/thesis/gate.yaml --backends thesis,box2d --seed 3 --trial 2 --out $o/trial.mp4
step $b essay --trials $essay_trials --out $o/essay
step $b accuracy --out $o/accuracy
step $b bench --json $o/bench.json
t1=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v c="the whole tour ($(nproc) cores)" 'BEGIN { printf "%-8.1f %s\n", b - a, c }'
