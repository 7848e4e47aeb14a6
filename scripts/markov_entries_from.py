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
stiffness pairs (left, right) given as flow lists in the scene file
(`stiffness_left:` and `stiffness_right:`, a row `- [...]` a line, row 0
first); the columns centred on the start's (ix from -(columns // 2)).
Exit status 2 on a field it cannot read or a layout without one
neighbour kind per gate kind and edge.
"""
import csv
import os
import sys

EDGES = {"bottom": (0, -1), "top": (0, 1), "left": (-1, 0), "right": (1, 0)}


def fail(msg):
    print(f"markov_entries_from.py: {msg}", file=sys.stderr)
    sys.exit(2)


def grid(path, key):
    rows, inside = [], False
    with open(path) as f:
        for n, line in enumerate(f, 1):
            s = line.strip()
            if s == key + ":":
                inside = True
            elif inside and s.startswith("- ["):
                try:
                    rows.append([float(v) for v in s[3:s.index("]")].split(",")])
                except ValueError:
                    fail(f"{path}:{n}: {key}: expected a row of numbers, got {s!r}")
            elif inside:
                break
    if not rows or len({len(r) for r in rows}) != 1:
        fail(f"{path}: {key}: expected rows of stiffnesses as flow lists, one a line")
    return rows


class Field:
    def __init__(self, path):
        self.left, self.right = grid(path, "stiffness_left"), grid(path, "stiffness_right")
        if len(self.left) != len(self.right) or len(self.left[0]) != len(self.right[0]):
            fail(f"{path}: stiffness_left and stiffness_right differ in size")
        self.rows, self.half = len(self.left), len(self.left[0]) // 2

    def kind(self, ix, iy):
        c = ix + self.half
        if 0 <= iy < self.rows and 0 <= c < len(self.left[0]):
            return (self.left[iy][c], self.right[iy][c])
        return None

    def came_from(self, ix, iy, edge):
        dx, dy = EDGES[edge]
        return self.kind(ix + dx, iy + dy)


def main():
    if len(sys.argv) != 5:
        fail("usage: markov_entries_from.py TRAIN_FIELD LAYOUT_FIELD ENTRIES OUT")
    train, layout = Field(sys.argv[1]), Field(sys.argv[2])
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
            if edge in EDGES and want.get((train.kind(ix, iy), edge)) != train.came_from(ix, iy, edge):
                continue
            w.writerow(row)
            kept += 1
    os.replace(part, sys.argv[4])
    print(f"{kept} of {total} entries kept")


if __name__ == "__main__":
    main()
