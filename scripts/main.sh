#!/usr/bin/env bash
# The main job: install what is missing, build, and run the essay's symmetric
# experiment (Table 3.1) on the thesis backend.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
scripts/build.sh
build/beamsim sweep configs/thesis/h1_symmetric.yaml --out out/h1
