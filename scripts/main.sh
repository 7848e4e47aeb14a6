#!/usr/bin/env bash
# The main job: install what is missing, build, and compare the two backends
# on the essay's symmetric experiment H1 (Table 3.1: 30 groups x 100 trials on
# each backend, same schedules). The report is out/h1-compare/report.md, its
# figures beside it (compare.png, and each backend's in out/h1-compare/<backend>/).
# It is the job's own output: a rerun replaces out/h1-compare and
# out/landscape (--overwrite), and says so first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
for d in out/h1-compare out/landscape; do
  [ -e "$d/manifest.json" ] && echo "scripts/main.sh: replacing $d (the result of an earlier run)"
done
status=0
build/beamsim compare configs/thesis/h1_symmetric.yaml --trajectories 10 --out out/h1-compare \
  --overwrite || status=$?
# 3 means the report lists disagreeing groups: a finding, not a failure.
if [ "$status" -ne 0 ] && [ "$status" -ne 3 ]; then
  exit "$status"
fi
build/beamsim plot out/h1-compare --quiet
build/beamsim landscape configs/thesis/gate.yaml --out out/landscape --overwrite  # the essay gate's landscape
echo "report: out/h1-compare/report.md, figures: out/h1-compare/compare.png and out/h1-compare/*/"
