#!/usr/bin/env python3
"""The essay's Fig. 3.1 through the Python module: H1's p_traverse over the
propulsive force F_prop (columns) and the random force's magnitude Rm
(rows), each with its Wilson 95% interval.

    PYTHONPATH=build/python python3 examples/fig3_1.py [--trials N] [--out DIR]

prints the table and writes DIR/fig3_1.dat (column row p_traverse ci95_lo
ci95_hi traversed trials), DIR/fig3_1.gp and, with gnuplot, DIR/fig3_1.png
(a cell per group, coloured by p_traverse and printed with it). The
numbers are those of `beamsim sweep configs/thesis/h1_symmetric.yaml`
with the same trials (docs/figures.md, Fig. 3.1)."""

import argparse
import os
import shutil
import subprocess

import beamsim

HERE = os.path.dirname(os.path.abspath(__file__))
FORCE = "effects.propulsion.force"
MAGNITUDE = "effects.random_force.magnitude"

GNUPLOT = """set terminal pngcairo size 900,560 font "DejaVu Sans,11"
set output "fig3_1.png"
set title "H1: p_{{traverse}} ({trials} trials a group, 95% intervals)"
set xlabel "F_{{prop}} (N)"
set ylabel "R_m (N)"
set cbrange [0:1]
set cblabel "p_{{traverse}}"
set palette defined (0 "#f7fbff", 1 "#08306b")
set xtics ({xtics})
set ytics ({ytics})
set xrange [-0.5:{xmax}]
set yrange [-0.5:{ymax}]
unset key
plot "fig3_1.dat" using 1:2:3 with image, \\
     "" using 1:2:(sprintf("%.2f\\n[%.2f, %.2f]", $3, $4, $5)):($3 > 0.5 ? 0xffffff : 0) \\
        with labels tc rgb variable
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--experiment", default=os.path.join(HERE, "..", "configs", "thesis",
                                                         "h1_symmetric.yaml"))
    ap.add_argument("--trials", type=int, default=None, help="trials a group (default: 100)")
    ap.add_argument("--threads", type=int, default=None)
    ap.add_argument("--out", default="fig3_1", help="where the figure goes")
    a = ap.parse_args()

    s = beamsim.sweep(a.experiment, trials=a.trials, threads=a.threads)
    groups = s["groups"]
    forces = sorted({g["params"][FORCE] for g in groups})
    magnitudes = sorted({g["params"][MAGNITUDE] for g in groups})
    cell = {(g["params"][FORCE], g["params"][MAGNITUDE]): g for g in groups}
    trials = groups[0]["trials"]

    print(f"p_traverse, {trials} trials a group (Wilson 95% interval)")
    print("Rm \\ F_prop " + "".join(f"{f:>20g}" for f in forces))
    for m in magnitudes:
        row = ""
        for f in forces:
            g = cell[(f, m)]
            lo, hi = g["ci95"]
            row += f"{g['p_traverse']:>8.2f} [{lo:.2f}, {hi:.2f}]"
        print(f"{m:>11g} {row}")

    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "fig3_1.dat"), "w") as f:
        f.write("# column row p_traverse ci95_lo ci95_hi traversed trials\n")
        for j, m in enumerate(magnitudes):
            for i, fp in enumerate(forces):
                g = cell[(fp, m)]
                f.write(f"{i} {j} {g['p_traverse']!r} {g['ci95'][0]!r} "
                        f"{g['ci95'][1]!r} {g['traversed']} {g['trials']}\n")
            f.write("\n")
    script = GNUPLOT.format(
        trials=trials, xmax=len(forces) - 0.5, ymax=len(magnitudes) - 0.5,
        xtics=", ".join(f'"{v:g}" {i}' for i, v in enumerate(forces)),
        ytics=", ".join(f'"{v:g}" {j}' for j, v in enumerate(magnitudes)))
    with open(os.path.join(a.out, "fig3_1.gp"), "w") as f:
        f.write(script)
    if shutil.which("gnuplot"):
        subprocess.run(["gnuplot", "fig3_1.gp"], cwd=a.out, check=True)
        print(f"wrote {os.path.join(a.out, 'fig3_1.png')}")
    else:
        print(f"wrote {os.path.join(a.out, 'fig3_1.dat')} and fig3_1.gp (no gnuplot to draw them)")


if __name__ == "__main__":
    main()
