#!/usr/bin/env bash
# The shape study (docs/shape.md): sweeps the disk, the capsule and the
# ellipse of equal area (configs/shape/) over propulsion, contact friction and
# three forcings of matched low-frequency power, then draws p_traverse with
# Wilson 95% intervals, one panel per forcing and friction, into
# OUT/shape_study.png (+ .svg, the table shape_study.csv).
#   scripts/shape_study.sh OUT [--backend B] [--trials N] [other sweep options]
# Box2D and Chipmunk hold the ellipse as a polygon and refuse it unless told:
# add --backend-opt ellipse=polygon with --backend box2d or chipmunk.
set -euo pipefail
out=${1:?usage: scripts/shape_study.sh OUT [sweep options]}
shift
here=$(cd "$(dirname "$0")/.." && pwd)
bin=${BEAMSIM:-$here/build/beamsim}
mkdir -p "$out"
for shape in disk capsule ellipse; do
	"$bin" sweep "$here/configs/shape/study_$shape.yaml" --quiet --out "$out/$shape" "$@"
done
python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
rows = []
for shape in ("disk", "capsule", "ellipse"):
    s = json.load(open(f"{out}/{shape}/summary.json"))
    for g in s["groups"]:
        p = g["params"]
        rows.append((shape, p["effects.random_force.model"], p["contact.friction"],
                     p["effects.propulsion.force"], g["traversed"], g["trials"],
                     g["p_traverse"], g["ci95"][0], g["ci95"][1]))
with open(f"{out}/shape_study.csv", "w") as f:
    f.write("shape,forcing,friction,f_prop,traversed,trials,p_traverse,ci_lo,ci_hi\n")
    for r in rows:
        f.write(",".join(str(v) for v in r) + "\n")
backend = json.load(open(f"{out}/disk/summary.json"))["backend"]
# One data block per (forcing, friction, shape), for gnuplot's index.
blocks, keys = [], []
for model in ("held", "ou", "white"):
    for mu in (0, 0.3):
        for shape in ("disk", "capsule", "ellipse"):
            keys.append((model, mu, shape))
            blocks.append([r for r in rows if r[1] == model and r[2] == mu and r[0] == shape])
with open(f"{out}/shape_study.dat", "w") as f:
    for b in blocks:
        for r in b:
            f.write(f"{r[3]} {r[6]} {r[7]} {r[8]}\n")
        f.write("\n\n")
gp = [f"set terminal pngcairo size 1200,1300 font 'Sans,11'",
      f"set output '{out}/shape_study.png'",
      "set multiplot layout 3,2 title 'p_{traverse} of bodies of equal area (314 m^2), "
      f"{backend} backend, Wilson 95% intervals' font 'Sans,13'",
      "set xrange [4.5:10.5]", "set yrange [0:1]", "set xtics 5, 1, 10",
      "set xlabel 'propulsion force F_{prop} (N)'", "set ylabel 'p_{traverse}'",
      "set key top left", "set grid"]
names = {"held": "held (50 Hz)", "ou": "Ornstein-Uhlenbeck ({/Symbol t} 0.01 s)",
         "white": "white"}
colours = {"disk": "#1b6ca8", "capsule": "#c0392b", "ellipse": "#27ae60"}
offset = {"disk": -0.12, "capsule": 0.0, "ellipse": 0.12}
for model in ("held", "ou", "white"):
    for mu in (0, 0.3):
        # two lines: on one, the Ornstein-Uhlenbeck panel's title is wider
        # than its half of the canvas and was cut at the edge
        gp.append(f"set title \"random force {names[model]}, R_m 20 N\\n"
                  f"contact friction {{/Symbol m}}_c = {mu}\"")
        plots = []
        for shape in ("disk", "capsule", "ellipse"):
            i = keys.index((model, mu, shape))
            plots.append(f"'{out}/shape_study.dat' index {i} using ($1+{offset[shape]}):2:3:4 "
                         f"with yerrorlines lw 2 pt 7 lc rgb '{colours[shape]}' title '{shape}'")
        gp.append("plot " + ", ".join(plots))
gp.append("unset multiplot")
open(f"{out}/shape_study.gp", "w").write("\n".join(gp) + "\n")
svg = [l.replace("pngcairo size 1200,1300", "svg size 1200,1300")
        .replace("shape_study.png", "shape_study.svg") for l in gp]
open(f"{out}/shape_study_svg.gp", "w").write("\n".join(svg) + "\n")
PY
gnuplot "$out/shape_study.gp"
gnuplot "$out/shape_study_svg.gp"
echo "wrote $out/shape_study.csv, $out/shape_study.png, $out/shape_study.svg"
