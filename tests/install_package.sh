#!/bin/sh
# The installed package as a user meets it: `cmake --install` into a fresh
# prefix, examples/ configured and built against it with
# find_package(beamsim CONFIG) (shared and static), the same program
# compiled with `pkg-config --cflags --libs beamsim` alone (and with the
# README's compile line exactly, run without LD_LIBRARY_PATH: the .pc file's
# rpath finds the library in a prefix that is not a system one), and all
# runs giving the installed program's own answer: the sweep's p_traverse
# per group equals that of `beamsim sweep` on the same experiment, trials
# and seed. The shared library exports exactly the functions and objects
# the installed headers declare BSIM_API. A backend's helpers are usable
# from outside the tree: examples/backend_helpers.c, built by CMake and by
# pkg-config alone, computes a beam's contact flag and an ellipse's gap
# with the installed beamsim/contact_flag.h and beamsim/body_shape.h and
# agrees with their closed forms, and the two headers compile as C++ (a
# backend may be written in it). The example plug-in, built against the
# package, is loaded and run by the installed program.
#   install_package.sh BUILD_DIR SOURCE_DIR WORK_DIR
set -eu
build=$1 src=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >"$work/install.log"
exp=$prefix/share/beamsim/configs/thesis/h1_symmetric.yaml
test -f "$exp" || { echo "not installed: $exp"; exit 1; }

cmake -S "$src/examples" -B "$work/examples" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release >"$work/configure.log"
cmake --build "$work/examples" >"$work/build.log"

pcdir=$(dirname "$(find "$prefix" -name beamsim.pc)")
libdir=$(dirname "$pcdir")
PKG_CONFIG_PATH=$pcdir cc -std=c17 -Wall -Werror -o "$work/pc_example" \
    "$src/examples/trial_and_sweep.c" $(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs beamsim)
cc -std=c17 -Wall -Wextra -Werror -o "$work/pc_backend_helpers" \
    "$src/examples/backend_helpers.c" $(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs beamsim) -lm
printf '#include <beamsim/contact_flag.h>\n#include <beamsim/body_shape.h>\n' |
    c++ -x c++ -std=c++17 -fsyntax-only -Wall -Wextra -Werror \
        $(PKG_CONFIG_PATH=$pcdir pkg-config --cflags beamsim) -

# README's compile line exactly, with its prefix $HOME/beamsim this one,
# run from the source tree's parent of examples/ into a.out in WORK: the
# program finds libbeamsim.so.0 through the rpath the .pc file gives, with
# no LD_LIBRARY_PATH.
readme_cc=$(grep '^    cc examples/trial_and_sweep.c ' "$src/README.md" | sed 's/^    //')
test -n "$readme_cc" || { echo "README.md has no 'cc examples/trial_and_sweep.c' line"; exit 1; }
mkdir -p "$work/readme"
(cd "$work/readme" && ln -sf "$src/examples" examples &&
 HOME=$work/home && mkdir -p "$HOME" && ln -sfn "$prefix" "$HOME/beamsim" &&
 export HOME && sh -c "$readme_cc")
test -x "$work/readme/a.out" || { echo "README's line built no a.out: $readme_cc"; exit 1; }
case $(grep '^Libs:' "$pcdir/beamsim.pc") in
*-rpath*) ;;
*) echo "beamsim.pc's Libs line has no rpath"; exit 1 ;;
esac

"$work/examples/trial_and_sweep" "$exp" 20 >"$work/shared.txt"
"$work/examples/trial_and_sweep_static" "$exp" 20 >"$work/static.txt"
env -u LD_LIBRARY_PATH "$work/pc_example" "$exp" 20 >"$work/pc.txt"
env -u LD_LIBRARY_PATH "$work/readme/a.out" "$exp" 20 >"$work/readme.txt"
"$work/examples/backend_helpers" >"$work/backend_helpers.txt" ||
    { cat "$work/backend_helpers.txt"; echo "backend_helpers (CMake) differs from its closed forms"; exit 1; }
env -u LD_LIBRARY_PATH "$work/pc_backend_helpers" >"$work/pc_backend_helpers.txt" ||
    { cat "$work/pc_backend_helpers.txt"; echo "backend_helpers (pkg-config) differs from its closed forms"; exit 1; }

# A backend of one's own, outside the tree: the example plug-in built by
# CMake against the package and by pkg-config alone, loaded by the installed
# program (--backend plugin:PATH, BEAMSIM_PLUGINS) and run.
cc -std=c17 -Wall -Wextra -Werror -shared -fPIC -o "$work/pc_gate_euler.so" \
    "$src/examples/plugin_gate_euler.c" $(PKG_CONFIG_PATH=$pcdir pkg-config --cflags --libs beamsim) -lm
"$prefix/bin/beamsim" sweep "$exp" --backend "plugin:$work/examples/libgate_euler.so" \
    --trials 2 --quiet --out "$work/plugin_sweep"
grep -q '"name": "gate_euler"' "$work/plugin_sweep/run.json" ||
    { echo "the plug-in's sweep does not record gate_euler"; exit 1; }
BEAMSIM_PLUGINS="$work/pc_gate_euler.so" "$prefix/bin/beamsim" backends >"$work/plugin_backends.txt"
grep -q '^gate_euler$' "$work/plugin_backends.txt" ||
    { echo "beamsim backends does not list the plug-in of BEAMSIM_PLUGINS"; exit 1; }
# The shared library brings only the bsim_ functions.
if nm -D --defined-only "$libdir/libbeamsim.so" | awk '{print $3}' | grep -v '^bsim_' | grep .; then
    echo "libbeamsim.so exports symbols outside bsim_"; exit 1
fi

# The ABI is the API: the functions and objects libbeamsim.so exports are
# those the installed headers declare BSIM_API (beamsim/base.h), no more (an
# internal function exported by accident) and no fewer (a declaration
# without a definition, which would fail only in a user's link). A
# declaration may run over lines; it ends at its ';'. Its name is the word
# before its first '(', or for an object the word before its ';' or '['.
nm -D --defined-only "$libdir/libbeamsim.so" | awk '$2 ~ /^[TDRB]$/ {print $3}' |
    sort -u >"$work/exported.txt"
awk '/^BSIM_API / {d = ""; on = 1} on {d = d " " $0} on && /;/ {print d; on = 0}' \
    "$prefix/include/beamsim/"*.h |
    sed -E -e 's/^([^(]*[^a-zA-Z0-9_])?([a-zA-Z_][a-zA-Z0-9_]*) *\(.*/\2/' \
           -e 's/^.*[^a-zA-Z0-9_]([a-zA-Z_][a-zA-Z0-9_]*) *[;[].*/\1/' |
    sort -u >"$work/declared.txt"
undeclared=$(comm -23 "$work/exported.txt" "$work/declared.txt")
if [ -n "$undeclared" ]; then
    echo "libbeamsim.so exports what no installed header declares BSIM_API:" $undeclared
    exit 1
fi
unexported=$(comm -13 "$work/exported.txt" "$work/declared.txt")
if [ -n "$unexported" ]; then
    echo "declared BSIM_API but not exported by libbeamsim.so:" $unexported
    exit 1
fi

# Wall time aside, the three runs print the same.
for f in shared static pc readme; do
    sed 's/ in [0-9.]* s$//' "$work/$f.txt" >"$work/$f.cmp"
done
cmp "$work/shared.cmp" "$work/static.cmp"
cmp "$work/shared.cmp" "$work/pc.cmp"
cmp "$work/shared.cmp" "$work/readme.cmp"
grep -q '^thesis ' "$work/shared.txt" && grep -q '^box2d ' "$work/shared.txt"

# The library's sweep is the program's.
"$prefix/bin/beamsim" sweep "$exp" --trials 20 --quiet --out "$work/cli"
grep -o '"p_traverse": *[0-9.e+-]*' "$work/cli/summary.json" | sed 's/.*: *//' |
    awk '{printf "%.3f\n", $1}' >"$work/cli_p.txt"
grep '^group' "$work/shared.txt" | awk '{print $4}' >"$work/lib_p.txt"
test -s "$work/lib_p.txt"
cmp "$work/lib_p.txt" "$work/cli_p.txt"

# The Python module, when the build has it: imported from the prefix by
# Debian's python3 with the prefix's dist-packages on PYTHONPATH (for the
# prefix /usr/local python3 finds it without), finding libbeamsim.so by its
# rpath, and its sweep the program's.
if [ -d "$build/python/beamsim" ]; then
    init=$(find "$prefix" -path '*/dist-packages/beamsim/__init__.py')
    test -n "$init" || { echo "the Python module is not installed under dist-packages"; exit 1; }
    site=$(dirname "$(dirname "$init")")
    py=/usr/bin/python3
    [ -x "$py" ] || py=python3
    env -u LD_LIBRARY_PATH PYTHONPATH="$site" "$py" -c '
import sys, beamsim
assert beamsim.__file__.startswith(sys.argv[2]), beamsim.__file__
for g in beamsim.sweep(sys.argv[1], trials=20)["groups"]:
    print("%.3f" % g["p_traverse"])' "$exp" "$site" >"$work/py_p.txt"
    cmp "$work/py_p.txt" "$work/cli_p.txt"
fi
echo "installed package: shared, static and pkg-config builds agree with beamsim sweep; a backend's helpers agree with their closed forms; the example plug-in runs"
