"""scripts/markov_entries_from.py against the trials' own order: the gate an
entry came from is the gate of the trial's entry before it."""

import csv
import os
import subprocess
import sys

from conftest import SRC, cli, config

SCRIPT = os.path.join(SRC, "scripts", "markov_entries_from.py")
TRAIN = config("markov", "kinds", "field_other_train.yaml")
COLUMNS = config("markov", "kinds", "field_other_cols11.yaml")
RANDOM = config("markov", "kinds", "field_other_r21.yaml")


def run(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args)], capture_output=True,
                          text=True)


def stiffness(path):
    """(left, right) of each gate (ix, iy) of a field, read here on its own."""
    rows = {"stiffness_left": [], "stiffness_right": []}
    key = None
    with open(path) as f:
        for line in f:
            s = line.strip()
            if s.rstrip(":") in rows:
                key = s.rstrip(":")
            elif key and s.startswith("- ["):
                rows[key].append([float(v) for v in s[3:-1].split(",")])
            else:
                key = None
    left, right = rows["stiffness_left"], rows["stiffness_right"]
    half = len(left[0]) // 2
    return {(c - half, iy): (left[iy][c], right[iy][c])
            for iy in range(len(left)) for c in range(len(left[0]))}


def test_kept_entries_came_from_the_layouts_neighbour(tmp_path):
    cli("sweep", config("markov", "kinds", "exp_other_train.yaml"), "--trials", 60,
        "--threads", 2, "--quiet", "--out", tmp_path / "train")
    entries = tmp_path / "train" / "gate_entries.csv"
    out = tmp_path / "kept.csv"
    p = run(TRAIN, COLUMNS, entries, out)
    assert p.returncode == 0, p.stderr
    with open(entries, newline="") as f:
        rows = list(csv.DictReader(f))
    with open(out, newline="") as f:
        kept = list(csv.DictReader(f))
    # a layout of columns: a gate's neighbours below and above are of its
    # own kind, those beside of the columns' kinds beside it
    train, layout = stiffness(TRAIN), stiffness(COLUMNS)
    want = {}
    for (ix, iy), k in layout.items():
        for edge, (dx, dy) in {"bottom": (0, -1), "top": (0, 1), "left": (-1, 0),
                               "right": (1, 0)}.items():
            if (ix + dx, iy + dy) in layout:
                want[(k, edge)] = layout[(ix + dx, iy + dy)]
    before = {}
    expected = []
    for r in rows:
        at = (int(r["ix"]), int(r["iy"]))
        prev = before.get((r["group"], r["trial"]))
        before[(r["group"], r["trial"])] = at
        if r["edge"] == "start":
            expected.append(r)
            continue
        assert prev is not None, r
        if want.get((train[at], r["edge"])) == train[prev]:
            expected.append(r)
    assert kept == expected
    assert 0 < len(kept) < len(rows)
    assert any(r["edge"] != "start" for r in kept)


def test_a_layout_of_mixed_neighbours_is_refused(tmp_path):
    entries = tmp_path / "gate_entries.csv"
    entries.write_text("group,trial,seq,ix,iy,edge\n")
    p = run(TRAIN, RANDOM, entries, tmp_path / "kept.csv")
    assert p.returncode == 2
    assert "field_other_r21.yaml" in p.stderr and "more than one kind" in p.stderr
    assert not (tmp_path / "kept.csv").exists()
