"""A lattice scene file's gate kinds, for the scripts that read them
(markov_entries_from.py, markov_nearest.py): the stiffness pairs (left,
right) given as flow lists (`stiffness_left:` and `stiffness_right:`, a row
`- [...]` a line, row 0 first), the columns centred on the start's (ix from
-(columns // 2)), as the fields of configs/markov/kinds are written."""
import sys


def fail(script, msg):
    print(f"{script}: {msg}", file=sys.stderr)
    sys.exit(2)


def grid(path, key, script):
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
                    fail(script, f"{path}:{n}: {key}: expected a row of numbers, got {s!r}")
            elif inside:
                break
    if not rows or len({len(r) for r in rows}) != 1:
        fail(script, f"{path}: {key}: expected rows of stiffnesses as flow lists, one a line")
    return rows


# A gate's edges: where the neighbour across each lies, and (INWARD) the way
# a body crossing it moves, the edge's inward normal.
EDGES = {"bottom": (0, -1), "top": (0, 1), "left": (-1, 0), "right": (1, 0)}
INWARD = {edge: (-dx, -dy) for edge, (dx, dy) in EDGES.items()}


class Field:
    def __init__(self, path, script):
        self.path = path
        self.left = grid(path, "stiffness_left", script)
        self.right = grid(path, "stiffness_right", script)
        if len(self.left) != len(self.right) or len(self.left[0]) != len(self.right[0]):
            fail(script, f"{path}: stiffness_left and stiffness_right differ in size")
        self.rows, self.columns = len(self.left), len(self.left[0])
        self.half = self.columns // 2

    def kind(self, ix, iy):
        c = ix + self.half
        if 0 <= iy < self.rows and 0 <= c < self.columns:
            return (self.left[iy][c], self.right[iy][c])
        return None

    def kinds(self):
        return sorted({(self.left[iy][c], self.right[iy][c])
                       for iy in range(self.rows) for c in range(self.columns)})

    def came_from(self, ix, iy, edge):
        """The kind of the neighbour across `edge` that a body entering gate
        (ix, iy) through it left (None outside the field)."""
        dx, dy = EDGES[edge]
        return self.kind(ix + dx, iy + dy)
