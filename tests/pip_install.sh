#!/bin/sh
# `pip install .` as a Python user runs it (docs/bindings.md, "pip install"):
# into a fresh virtual environment that sees the system's NumPy
# (--system-site-packages), offline (--no-index, --no-build-isolation), from a
# copy of the files pip reads, the library taken from the build
# (BEAMSIM_BUILD_DIR); then, from another folder, the venv's python3 imports
# the installed package (not the source's), finds the library it carries,
# and its sweep's p_traverse per group is what `beamsim sweep` writes.
#   pip_install.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1 src=$2 work=$3
rm -rf "$work"
mkdir -p "$work/src/bindings"
cp -r "$src/pyproject.toml" "$src/setup.py" "$src/setup.cfg" "$src/README.md" "$src/include" \
      "$work/src/"
cp -r "$src/bindings/python" "$work/src/bindings/"
python3=/usr/bin/python3
[ -x "$python3" ] || python3=python3
"$python3" -m venv --system-site-packages "$work/venv"
BEAMSIM_BUILD_DIR="$build" "$work/venv/bin/pip" install --no-index --no-build-isolation \
    "$work/src" >"$work/pip.log" 2>&1 || { cat "$work/pip.log"; exit 1; }
exp=$src/configs/thesis/h1_symmetric.yaml
"$build/beamsim" sweep "$exp" --trials 20 --quiet --out "$work/cli"
grep -o '"p_traverse": *[0-9.e+-]*' "$work/cli/summary.json" | sed 's/.*: *//' |
    awk '{printf "%.6f\n", $1}' >"$work/cli_p.txt"
cd "$work"
env -u PYTHONPATH -u LD_LIBRARY_PATH "$work/venv/bin/python" -c '
import sys, beamsim
assert beamsim.__file__.startswith(sys.argv[2]), beamsim.__file__
for g in beamsim.sweep(sys.argv[1], trials=20)["groups"]:
    print("%.6f" % g["p_traverse"])' "$exp" "$work/venv" >"$work/py_p.txt"
test -s "$work/py_p.txt"
cmp "$work/py_p.txt" "$work/cli_p.txt"
echo "pip install: the venv's beamsim sweeps as the program does"
