#!/usr/bin/env python3
"""Nearest-neighbour walks: a lattice's final locations predicted from the
exact gate visits of training fields, without bins (docs/markov.md, "A
kernel over exact states").

    scripts/markov_nearest.py FIELD --out DIR [--train TDIR] [--trials N]
        [--k K] [--walks W] [--seed S] [--threads T] [--exe PATH]
        [--force F] [--validate VDIR]

For each gate kind of FIELD a training field is swept by `beamsim sweep`:
FIELD's physics (at F_prop = F with --force F) on a 21 x 21 lattice of
FIELD's kinds drawn at random (by --seed), the start gate of that kind,
under the essay's protocol, N trials (default 10,000), in TDIR/train_I/
(default DIR). A run that finds the same training field swept there reuses
it, so fields of the same kinds and physics share one TDIR as they share
maps. The trials' gate entries are visits: a gate of kind K entered through
an edge in an exact state (position along the edge, velocity) that left
into the trial's next entry, in that entry's state, or was stuck there (the
trial's last gate, for gate_time); a gate left out of the field, or in
which the trial ended otherwise, has no known exit and is no visit. The
start gate's are the start's visits of its kind.

FIELD's body starts in its gate (0, 0), row 0's middle, as the fields of
configs/markov/kinds do. A walk on FIELD, under the essay's protocol as the
chain: the start gate's exit is one of its kind's start visits at random;
then, in gate g of kind K entered through edge e in state s, one of the k
visits (--k, default 20) of kind K through e nearest to s is drawn at
random, and its exit is g's: stuck in g, into the neighbour across the
exit's edge in the exit's exact state, or out of the field (the end, a
side). The distance is in units of the default bins' widths (position /
(edge / 14), speed / (v_max / 6), direction / (pi / 13); v_max as `markov
build` sets it). A body leaving row 0 downwards enters it again through its
bottom, as in the chain. The walks are seeded (--seed): the same numbers on
every run.

DIR/prediction.csv: location, p, walks; DIR/tv.json: the training sweeps'
CPU time and the walks', the visits, those stuck, the gates entered on the
training fields' edges by their exits (visits() says why), and with
--validate VDIR (`markov validate` of FIELD) the total variation from its
simulation under each protocol (also printed) and the walks' own sampling
error. Needs NumPy and SciPy (scripts/deps.sh). Exit status 2 on bad input,
1 if a walk is still in the field after 10,000 gates.
"""
import argparse
import csv
import json
import math
import os
import re
import resource
import subprocess
import sys
import time
from collections import defaultdict

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lattice_field import INWARD, Field, fail as field_fail  # noqa: E402

SCRIPT = "markov_nearest.py"
TRAIN_SIZE = 21
BINS = (14, 6, 13)  # the default bins: the distance's units
V_MAX, V_MAX_TIME = 40.0, 40.0 / 7.0  # bsim_markov_bins_v_max
MOST_GATES = 10000


def fail(msg):
    field_fail(SCRIPT, msg)


def number(text, pattern, what, path, default=None):
    m = re.search(pattern, text)
    if not m:
        if default is None:
            fail(f"{path}: expected {what}")
        return default
    return float(m.group(1))


class Physics:
    """What the walks need of FIELD beyond its kinds."""

    def __init__(self, path, force=None):
        text = open(path).read()
        num = r"([-+0-9.eE]+)"
        if force is not None:  # --force: the propulsion of FIELD's physics replaced
            text, n = re.subn(r"(propulsion:\s*\{[^}]*force:\s*)[-+0-9.eE]+",
                              lambda m: f"{m.group(1)}{force:g}", text)
            if n != 1:
                fail(f"{path}: --force: expected one effects.propulsion {{ force: F }}")
        self.width = number(text, r"gate:\s*\{[^}]*width:\s*" + num, "gate: { width: W }", path)
        self.depth = number(text, r"gate:\s*\{[^}]*depth:\s*" + num, "gate: { depth: D }", path)
        mass = number(text, r"body:\s*\{[^}]*mass:\s*" + num, "body: { mass: M }", path)
        force = number(text, r"propulsion:\s*\{[^}]*force:\s*" + num, "", path, 0.0)
        self.v_max = max(V_MAX, abs(force) / mass * V_MAX_TIME)
        self.dt = number(text, r"integration:\s*\{[^}]*dt:\s*" + num, "", path, 0.004)
        gate_time = number(text, r"termination:\s*\{[^}]*gate_time:\s*" + num, "", path, 0.0)
        self.gate_steps = round(gate_time / self.dt) if gate_time > 0 else 3000
        self.text = text

    def feature(self, edge, pos, vx, vy):
        n = INWARD[edge]
        t = (abs(n[1]), abs(n[0]))
        lo, length = ((-0.5 * self.width, self.width) if edge in ("bottom", "top")
                      else (0.0, self.depth))
        a = math.atan2(vx * t[0] + vy * t[1], vx * n[0] + vy * n[1])
        return ((pos - lo) / length * BINS[0], math.hypot(vx, vy) / self.v_max * BINS[1],
                (a + 0.5 * math.pi) / math.pi * BINS[2])


def train_scene(field, phys, kinds, start, rng, name):
    """FIELD's text with its lattice made a 21 x 21 field of kinds at random,
    kind `start` at the start gate, under the essay's protocol."""
    lay = [[kinds[rng.integers(len(kinds))] for _ in range(TRAIN_SIZE)]
           for _ in range(TRAIN_SIZE)]
    lay[0][TRAIN_SIZE // 2] = start
    out, in_lattice = [], False
    for line in phys.text.splitlines():
        if line.startswith("#"):
            continue
        if line.startswith("name:"):
            out.append(f"name: {name}")
            continue
        if line and not line.startswith((" ", "#")):
            in_lattice = line.startswith("lattice:")
            if in_lattice:
                out.append(line)
                out.append(f"  columns: {TRAIN_SIZE}\n  rows: {TRAIN_SIZE}\n  protocol: essay")
                for side, key in ((0, "stiffness_left"), (1, "stiffness_right")):
                    out.append(f"  {key}:")
                    out += ["    - [" + ", ".join(f"{k[side]:g}" for k in row) + "]"
                            for row in lay]
                continue
            if line.startswith("termination:"):
                line = re.sub(r"success_y:\s*[-+0-9.eE]+",
                              f"success_y: {phys.depth * TRAIN_SIZE:g}", line)
                line = re.sub(r"side_x:\s*[-+0-9.eE]+",
                              f"side_x: {0.5 * phys.width * TRAIN_SIZE:g}", line)
        elif in_lattice and re.match(r"\s+(columns|rows|protocol|stiffness\w*):|\s+- \[", line):
            continue
        out.append(line)
    return "\n".join(out) + "\n"


def sweep_training(args, field, phys):
    kinds = field.kinds()
    rng = np.random.default_rng(args.seed)
    dirs = []
    for i, start in enumerate(kinds):
        d = os.path.join(args.train or args.out, f"train_{i}")
        dirs.append(d)
        os.makedirs(d, exist_ok=True)
        files = {"field.yaml": train_scene(field, phys, kinds, start, rng, f"train_{i}"),
                 "exp.yaml": f"scene: field.yaml\ntrials: {args.trials}\nseed: {args.seed + i}\n"
                             f"grid:\n  integration.dt: [{phys.dt:g}]\n"}
        if os.path.exists(os.path.join(d, "cpu_seconds")) and all(
                os.path.exists(os.path.join(d, n)) and open(os.path.join(d, n)).read() == text
                for n, text in files.items()):
            continue  # this very training field, swept before
        for n, text in files.items():
            with open(os.path.join(d, n), "w") as f:
                f.write(text)
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        p = subprocess.run([args.exe, "sweep", os.path.join(d, "exp.yaml"), "--quiet",
                            "--overwrite", "--threads", str(args.threads),
                            "--out", os.path.join(d, "sweep")], capture_output=True, text=True)
        if p.returncode != 0:
            fail(f"beamsim sweep of the training field {d}/field.yaml: {p.stderr.strip()}")
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        with open(os.path.join(d, "cpu_seconds"), "w") as f:  # the sweep's, written last
            f.write(f"{after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime:.3f}\n")
    return dirs


def visits(dirs, phys, on_edge):
    """(kind, edge) -> (features, exits) and kind -> start exits; an exit is
    "stuck" or (edge, pos, vx, vy). on_edge counts the gates entered on the
    training fields' edges (the last row, the outer columns) by what is
    known of their exits: a gate there whose exit left the field is no
    visit, while one stuck there is, so the visits kept there are stuck
    more often than all of them were."""
    pool, starts = defaultdict(lambda: ([], [])), defaultdict(list)
    for d in dirs:
        field = Field(os.path.join(d, "field.yaml"), SCRIPT)
        sw = os.path.join(d, "sweep")
        with open(os.path.join(sw, "trials.csv"), newline="") as f:
            end = {(r["group"], r["trial"]): (r["location"], int(r["steps"]))
                   for r in csv.DictReader(f)}
        trial = defaultdict(list)
        with open(os.path.join(sw, "gate_entries.csv"), newline="") as f:
            for r in csv.DictReader(f):
                trial[(r["group"], r["trial"])].append(r)
        for key, es in trial.items():
            location, steps = end[key]
            for j, e in enumerate(es):
                ix, iy = int(e["ix"]), int(e["iy"])
                edge_gate = iy == field.rows - 1 or abs(ix) == field.half
                if j + 1 < len(es):
                    n = es[j + 1]
                    out = (n["edge"], float(n["pos"]), float(n["vx"]), float(n["vy"]))
                elif (location == f"stuck:{ix}:{iy}" and
                      steps - int(e["step"]) >= phys.gate_steps):
                    out = "stuck"
                else:
                    on_edge["exit unknown"] += edge_gate
                    continue
                on_edge["stuck" if out == "stuck" else "left"] += edge_gate
                k = field.kind(ix, iy)
                if e["edge"] == "start":
                    starts[k].append(out)
                else:
                    f = phys.feature(e["edge"], float(e["pos"]), float(e["vx"]), float(e["vy"]))
                    pool[(k, e["edge"])][0].append(f)
                    pool[(k, e["edge"])][1].append(out)
    return pool, starts


def walk(field, phys, pool, starts, k, n_walks, seed):
    trees = {key: (cKDTree(np.array(f)), exits) for key, (f, exits) in pool.items()}
    rng = np.random.default_rng(seed)

    def leads(ix, iy, out):
        edge, pos, vx, vy = out  # entering the next gate through `edge`
        dx, dy = INWARD[edge]
        jx, jy = ix + dx, iy + dy
        if jy >= field.rows:
            return f"end:{ix}"
        if abs(jx) > field.half:
            return f"side:{iy}"
        if jy < 0:  # below row 0: row 0's gate again, through its bottom
            return (ix, 0, "bottom", pos, vx, -vy)
        return (jx, jy, edge, pos, vx, vy)

    first = starts.get(field.kind(0, 0))
    if not first:
        fail("no start visit of the start gate's kind in the training fields")
    state = []
    for i in rng.integers(len(first), size=n_walks):
        out = first[i]
        state.append("stuck:0:0" if out == "stuck" else leads(0, 0, out))
    for _ in range(MOST_GATES):
        by = defaultdict(list)
        for i, s in enumerate(state):
            if isinstance(s, tuple):
                by[(field.kind(s[0], s[1]), s[2])].append(i)
        if not by:
            break
        for key in sorted(by):
            idx = by[key]
            if key not in trees:
                fail(f"no visit of kind {key[0]} through its {key[1]} in the training fields")
            tree, exits = trees[key]
            q = np.array([phys.feature(*state[i][2:]) for i in idx])
            kk = min(k, tree.n)
            _, near = tree.query(q, k=kk)
            near = np.asarray(near).reshape(len(idx), kk)
            pick = near[np.arange(len(idx)), rng.integers(kk, size=len(idx))]
            for i, p in zip(idx, pick):
                ix, iy = state[i][0], state[i][1]
                out = exits[p]
                state[i] = f"stuck:{ix}:{iy}" if out == "stuck" else leads(ix, iy, out)
    count = defaultdict(int)
    for s in state:
        count[s if isinstance(s, str) else "unfinished"] += 1
    return count


def total_variation(p, path, protocol):
    sim = {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r["protocol"] == protocol:
                sim[r["location"]] = float(r["p_sim"])
    if not sim:
        fail(f"{path}: no rows of the {protocol} protocol")
    return 0.5 * sum(abs(p.get(x, 0.0) - sim.get(x, 0.0)) for x in set(p) | set(sim))


def main():
    ap = argparse.ArgumentParser(prog=SCRIPT, description=__doc__.split("\n\n")[0])
    ap.add_argument("field")
    ap.add_argument("--out", required=True)
    ap.add_argument("--trials", type=int, default=10000)
    ap.add_argument("--k", type=int, default=20)
    ap.add_argument("--walks", type=int, default=200000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--exe", default="build/beamsim")
    ap.add_argument("--validate")
    ap.add_argument("--train")
    ap.add_argument("--force", type=float)
    args = ap.parse_args()
    for name in ("trials", "k", "walks", "threads"):
        if getattr(args, name) < 1:
            fail(f"--{name}: expected an integer >= 1, got {getattr(args, name)}")
    field, phys = Field(args.field, SCRIPT), Physics(args.field, args.force)
    vpath = os.path.join(args.validate, "validate.csv") if args.validate else None
    if vpath and not os.path.isfile(vpath):
        fail(f"--validate {args.validate}: expected a `markov validate` output (no validate.csv)")
    os.makedirs(args.out, exist_ok=True)
    dirs = sweep_training(args, field, phys)
    c0 = time.process_time()
    on_edge = defaultdict(int)
    pool, starts = visits(dirs, phys, on_edge)
    count = walk(field, phys, pool, starts, args.k, args.walks, args.seed)
    p = {x: n / args.walks for x, n in count.items()}
    result = {"walks": args.walks, "k": args.k, "training_trials": args.trials * len(dirs),
              "visits": sum(len(v[1]) for v in pool.values()),
              "visits_stuck": sum(o == "stuck" for v in pool.values() for o in v[1]),
              "on_training_edge": dict(on_edge),
              "training_cpu_seconds": sum(float(open(os.path.join(d, "cpu_seconds")).read())
                                          for d in dirs),
              "walk_cpu_seconds": time.process_time() - c0,
              # the expected TV of W walks from their own distribution
              "tv_walks": 0.5 * sum(math.sqrt(2 * q * (1 - q) / (math.pi * args.walks))
                                    for q in p.values())}
    part = os.path.join(args.out, "prediction.csv.part")
    with open(part, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(["location", "p", "walks"])
        for x in sorted(count):
            w.writerow([x, f"{p[x]:.9g}", count[x]])
    os.replace(part, os.path.join(args.out, "prediction.csv"))
    if vpath:
        for protocol in ("essay", "world"):
            result[f"tv_{protocol}"] = total_variation(p, vpath, protocol)
        print(f"TV essay {result['tv_essay']:.3f} world {result['tv_world']:.3f} "
              f"(walks' own {result['tv_walks']:.3f}; k {args.k}, {args.walks} walks, "
              f"{result['training_trials']} training trials, {result['visits']} visits)")
    with open(os.path.join(args.out, "tv.json.part"), "w") as f:
        json.dump(result, f, indent=1)
    os.replace(os.path.join(args.out, "tv.json.part"), os.path.join(args.out, "tv.json"))
    if count.get("unfinished"):
        print(f"{SCRIPT}: {count['unfinished']} walks still in the field after {MOST_GATES} "
              "gates", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
