#!/usr/bin/env python3
"""Which bodies of a stored sweep got past the gate, traversed or not.

    scripts/gate_passes.py DIR [Y]

Reads DIR/trials.csv (beamsim sweep) and counts, per group (the grid
columns), the traversals and the side exits on either side of the line
y = Y (default 30 m, the essay gate's pivot line). A side exit beyond Y
left through the side boundary after its centre had passed the pivot
line, so, as the body cannot overlap a pivot, through the gate between
the pivots: it got past the beams and ran out sideways before it reached
success_y. "passed" = traversed + side exits beyond Y. Proportions come
with Wilson's 95% interval; times are the medians of t_end, s, and |vx|
the median lateral speed at the end (at classify_y for a traversal),
m/s. Standard library only.
"""
import csv
import math
import sys
from collections import defaultdict

FIXED = ("group,trial,outcome,type,steps,t_end,x_end,y_end,vx_end,max_theta1,"
         "max_theta2,e_start,e_end,work_in,losses,residual,overlap_max,final_ix,"
         "final_iy,location,path,iteration_limits,clamps,t_exit,heading_end,"
         "angular_velocity_end,turn_end,turn_max").split(",")


def wilson(x, n, z=1.959963984540054):
    if n == 0:
        return (float("nan"), float("nan"))
    p = x / n
    d = 1 + z * z / n
    c = (p + z * z / (2 * n)) / d
    h = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / d
    return (max(0.0, c - h), min(1.0, c + h))


def median(v):
    if not v:
        return float("nan")
    v = sorted(v)
    m = len(v) // 2
    return v[m] if len(v) % 2 else 0.5 * (v[m - 1] + v[m])


def pct(x, n):
    lo, hi = wilson(x, n)
    return "%.1f [%.1f, %.1f]" % (100 * x / n, 100 * lo, 100 * hi)


def main(argv):
    if len(argv) not in (2, 3):
        sys.stderr.write("usage: scripts/gate_passes.py DIR [Y]\n")
        return 2
    path = argv[1].rstrip("/") + "/trials.csv"
    try:
        line_y = float(argv[2]) if len(argv) == 3 else 30.0
    except ValueError:
        sys.stderr.write("gate_passes.py: Y: expected a number, got %s\n" % argv[2])
        return 2
    try:
        f = open(path, newline="")
    except OSError as e:
        sys.stderr.write("gate_passes.py: %s: %s\n" % (path, e.strerror))
        return 2
    with f:
        rows = csv.DictReader(f)
        keys = [k for k in rows.fieldnames or [] if k not in FIXED]
        if "outcome" not in (rows.fieldnames or []):
            sys.stderr.write("gate_passes.py: %s: not a trials.csv (no outcome column)\n" % path)
            return 2
        groups = defaultdict(lambda: {"n": 0, "trav": 0, "before": 0, "beyond": 0,
                                      "stuck": 0, "t_trav": [], "t_beyond": [],
                                      "vx_trav": [], "vx_beyond": []})
        order = []
        for r in rows:
            g = int(r["group"])
            if g not in groups:
                order.append((g, tuple(r[k] for k in keys)))
            s = groups[g]
            s["n"] += 1
            if r["outcome"] == "traversed":
                s["trav"] += 1
                s["t_trav"].append(float(r["t_end"]))
                s["vx_trav"].append(abs(float(r["vx_end"])))
            elif r["outcome"] == "side_exit":
                if float(r["y_end"]) >= line_y:
                    s["beyond"] += 1
                    s["t_beyond"].append(float(r["t_end"]))
                    s["vx_beyond"].append(abs(float(r["vx_end"])))
                else:
                    s["before"] += 1
            elif r["outcome"] == "stuck":
                s["stuck"] += 1
    print("# %s, side exits split at y = %g m" % (path, line_y))
    print(",".join(keys + ["trials", "traversed", "side_before", "side_beyond", "stuck",
                           "p_traverse % [95%]", "p_passed % [95%]",
                           "t_traverse", "t_side_beyond", "vx_traverse", "vx_side_beyond"]))
    for g, vals in sorted(order):
        s = groups[g]
        n = s["n"]
        print(",".join(list(vals) + [
            str(n), str(s["trav"]), str(s["before"]), str(s["beyond"]), str(s["stuck"]),
            '"%s"' % pct(s["trav"], n), '"%s"' % pct(s["trav"] + s["beyond"], n),
            "%.2f" % median(s["t_trav"]), "%.2f" % median(s["t_beyond"]),
            "%.1f" % median(s["vx_trav"]), "%.1f" % median(s["vx_beyond"])]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
