"""scripts/gate_passes.py against a sweep's trials.csv counted here: per
group, the traversals, the side exits before and beyond the line y = Y,
the stuck trials, and "passed" = traversed + side exits beyond Y, with
Wilson's interval; bad input exits 2 with one line."""

import csv
import io
import os
import subprocess
import sys

from conftest import SRC, cli, config

SCRIPT = os.path.join(SRC, "scripts", "gate_passes.py")


def run_script(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args)], capture_output=True,
                          text=True)


def test_counts_match_trials(tmp_path):
    out = tmp_path / "s"
    cli("sweep", config("thesis", "h1_symmetric.yaml"), "--trials", 40, "--grid",
        "effects.propulsion.force=6,8", "--grid", "effects.random_force.magnitude=20,40",
        "--out", out, "--quiet", "--threads", 2)
    want = {}
    with open(out / "trials.csv", newline="") as f:
        for r in csv.DictReader(f):
            g = want.setdefault(int(r["group"]), [0, 0, 0, 0, 0])
            g[0] += 1
            o = r["outcome"]
            if o == "traversed":
                g[1] += 1
            elif o == "side_exit":
                g[3 if float(r["y_end"]) >= 30.0 else 2] += 1
            elif o == "stuck":
                g[4] += 1
    p = run_script(out)
    assert p.returncode == 0, p.stderr
    lines = [l for l in p.stdout.splitlines() if not l.startswith("#")]
    rows = list(csv.DictReader(io.StringIO("\n".join(lines))))
    assert len(rows) == len(want) == 4
    for row, (g, counts) in zip(rows, sorted(want.items())):
        got = [int(row[k]) for k in
               ("trials", "traversed", "side_before", "side_beyond", "stuck")]
        assert got == counts, (g, got, counts)
        passed = float(row["p_passed % [95%]"].split()[0])
        assert abs(passed - 100.0 * (counts[1] + counts[3]) / counts[0]) < 0.051
    # the line moved past every side exit: none beyond it
    p = run_script(out, 1e6)
    assert p.returncode == 0, p.stderr
    rows = list(csv.DictReader(io.StringIO(
        "\n".join(l for l in p.stdout.splitlines() if not l.startswith("#")))))
    assert all(int(r["side_beyond"]) == 0 for r in rows)


def test_bad_input(tmp_path):
    for args, word in (((), "usage"), ((tmp_path / "none",), "trials.csv"),
                       ((tmp_path, "thirty"), "expected a number")):
        p = run_script(*args)
        assert p.returncode == 2
        assert len(p.stderr.splitlines()) == 1 and word in p.stderr, p.stderr
