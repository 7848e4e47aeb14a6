#!/usr/bin/env python3
"""Keep the gate entries of a training sweep that came from the neighbour a
layout has there (docs/markov.md, "A held-out physics").

    scripts/markov_entries_from.py TRAIN_FIELD LAYOUT_FIELD ENTRIES OUT

ENTRIES is the gate_entries.csv of a sweep of TRAIN_FIELD. An entry into a
gate of kind K through its bottom, top, left or right edge came from the
neighbour across that edge. In LAYOUT_FIELD every gate of kind K entered
through one edge must have neighbours of one kind there; the entries kept
(to OUT, the same columns) are those whose neighbour is of that kind, and
the start's. Maps built on them (`markov build LAYOUT --entries OUT`) draw
each bin's states from entries out of the neighbours the layout has, as
maps split by the neighbour a body came from would for it. The kinds are
stiffness pairs (left, right), read as lattice_field.py says. Exit status
2 on a field it cannot read or a layout without one neighbour kind per gate
kind and edge.
"""
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lattice_field import EDGES, Field, fail as field_fail  # noqa: E402

SCRIPT = "markov_entries_from.py"


def fail(msg):
    field_fail(SCRIPT, msg)


def main():
    if len(sys.argv) != 5:
        fail("usage: markov_entries_from.py TRAIN_FIELD LAYOUT_FIELD ENTRIES OUT")
    train, layout = Field(sys.argv[1], SCRIPT), Field(sys.argv[2], SCRIPT)
    want = {}
    for iy in range(layout.rows):
        for ix in range(-layout.half, layout.half + 1):
            for edge in EDGES:
                f = layout.came_from(ix, iy, edge)
                if f is None:
                    continue
                k = (layout.kind(ix, iy), edge)
                if want.setdefault(k, f) != f:
                    fail(f"{sys.argv[2]}: gates of kind {k[0]} entered through the {edge} "
                         "come from more than one kind")
    kept = total = 0
    part = sys.argv[4] + ".part"  # OUT appears whole or not at all
    with open(sys.argv[3], newline="") as src, open(part, "w", newline="") as dst:
        r, w = csv.DictReader(src), None
        for row in r:
            if w is None:
                w = csv.DictWriter(dst, fieldnames=r.fieldnames, lineterminator="\n")
                w.writeheader()
            total += 1
            edge, ix, iy = row["edge"], int(row["ix"]), int(row["iy"])
            if edge in EDGES and (want.get((train.kind(ix, iy), edge)) !=
                                  train.came_from(ix, iy, edge)):
                continue
            w.writerow(row)
            kept += 1
    os.replace(part, sys.argv[4])
    print(f"{kept} of {total} entries kept")


if __name__ == "__main__":
    main()
