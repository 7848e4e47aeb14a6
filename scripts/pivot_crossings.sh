#!/usr/bin/env bash
# Where the traversals of a stored sweep crossed a line y = Y (default 30 m,
# the essay gate's pivot line): each traversed trial of DIR/trials.csv is
# replayed with `beamsim run --trajectory` (same scene, backend, options,
# seed, group, trial and overrides, from DIR/run.json, DIR/inputs/ and the
# trials.csv columns named by the grid's keys), and x where the body centre
# last crossed y = Y going forward (the crossing that led to the traversal;
# a body thrown back may have crossed before) is taken from the trajectory.
#
#   scripts/pivot_crossings.sh DIR [Y]
#
# Prints one line per traversal (group, trial, x) to DIR/crossings.csv and a
# summary: how many crossed between the pivots (|x| < 25 m), over a beam's
# pivot end (25 <= |x| < 35 m) and clear of the beams altogether (|x| >= 35
# m = pivot + body radius, walking around the gate), and quantiles of |x|.
set -euo pipefail
dir=${1:?usage: scripts/pivot_crossings.sh DIR [Y]}
line_y=${2:-30}
cd "$(dirname "$0")/.."
exe=build/beamsim
[ -x "$exe" ] || { echo "build first (scripts/build.sh)" >&2; exit 2; }
run_json="$dir/run.json"
backend=$(grep -o '"backends": \[{"name": "[^"]*"' "$run_json" | sed 's/.*"name": "//; s/"$//')
seed=$(grep -o '"seed": [0-9]*' "$run_json" | head -1 | sed 's/.*: //')
# every knob as --backend-opt
opts=$(grep -o '"options": {[^}]*}' "$run_json" | head -1 | sed 's/"options": {//; s/}$//' |
  tr ',' '\n' | sed -n 's/^ *"\([^"]*\)": "\([^"]*\)".*/--backend-opt \1=\2/p' | tr '\n' ' ')
# the stored experiment's set: entries as --set
sets=$(awk '/^set:/{s=1; next} /^[a-z]/{s=0} s && /:/{sub(/#.*/, ""); k=$1; sub(/:$/, "", k);
  $1=""; sub(/^ +/, ""); sub(/ +$/, ""); printf "--set %s=%s ", k, $0}' "$dir/inputs/experiment.yaml")
out="$dir/crossings.csv"
echo "group,trial,x" > "$out"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# columns after overlap_max are the grid's keys
header=$(head -1 "$dir/trials.csv")
first_param=$(echo "$header" | tr ',' '\n' | grep -n '^overlap_max$' | cut -d: -f1)
keys=$(echo "$header" | cut -d, -f$((first_param + 1))-)
tail -n +2 "$dir/trials.csv" | while IFS= read -r row; do
  IFS=, read -r g t outcome _ <<< "$row"
  [ "$outcome" = traversed ] || continue
  values=$(echo "$row" | cut -d, -f$((first_param + 1))-)
  grid=$(paste -d= <(echo "$keys" | tr ',' '\n') <(echo "$values" | tr ',' '\n') | sed 's/^/--set /' | tr '\n' ' ')
  # shellcheck disable=SC2086
  "$exe" run "$dir/inputs/scene.yaml" --backend "$backend" $opts --seed "$seed" --group "$g" \
    --trial "$t" $sets $grid --trajectory "$tmp/t.csv" > /dev/null
  x=$(awk -F, -v Y="$line_y" 'NR > 1 && $3 >= Y && (NR == 2 || below) { x = $2 }
    NR > 1 { below = $3 < Y } END { print x }' "$tmp/t.csv")
  echo "$g,$t,$x" >> "$out"
done
awk -F, 'NR > 1 { a = $3 < 0 ? -$3 : $3; print a }' "$out" | sort -g | awk -v Y="$line_y" -v f="$out" '
  { v[NR] = $1; if ($1 < 25) inside++; else if ($1 < 35) ends++; else around++ }
  END {
    if (NR == 0) { print "no traversals"; exit }
    printf "%d traversals crossed y = %g m: %d between the pivots (|x| < 25 m), %d over a pivot end (25-35 m), %d clear of the beams (|x| >= 35 m)\n", NR, Y, inside, ends, around
    printf "|x| quantiles 10%% / 50%% / 90%%: %.1f / %.1f / %.1f m; per trial: %s\n", v[int(0.1 * NR) + 1], v[int(0.5 * NR) + 1], v[int(0.9 * NR) + 1], f
  }'
