"""examples/fig3_1.py, the essay's Fig. 3.1 through the module: its data
file holds, cell by cell, p_traverse and the interval of summary.json of
`beamsim sweep` on H1 with the same trials."""

import json
import os
import subprocess
import sys

from conftest import SRC, cli

FORCE = "effects.propulsion.force"
MAGNITUDE = "effects.random_force.magnitude"


def test_fig3_1_is_the_sweep(h1, tmp_path):
    out = tmp_path / "fig"
    p = subprocess.run([sys.executable, os.path.join(SRC, "examples", "fig3_1.py"),
                        "--trials", "3", "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    cli("sweep", h1, "--trials", 3, "--out", tmp_path / "cli")
    with open(tmp_path / "cli" / "summary.json") as f:
        groups = json.load(f)["groups"]
    forces = sorted({g["params"][FORCE] for g in groups})
    magnitudes = sorted({g["params"][MAGNITUDE] for g in groups})
    rows = [line.split() for line in (out / "fig3_1.dat").read_text().splitlines()
            if line and not line.startswith("#")]
    assert len(rows) == len(groups) == len(forces) * len(magnitudes)
    for i, j, p_traverse, lo, hi, traversed, trials in rows:
        g = next(g for g in groups if g["params"][FORCE] == forces[int(i)] and
                 g["params"][MAGNITUDE] == magnitudes[int(j)])
        assert float(p_traverse) == g["p_traverse"]
        assert [float(lo), float(hi)] == g["ci95"]
        assert int(traversed) == g["traversed"] and int(trials) == g["trials"] == 3
    assert "p_traverse, 3 trials a group" in p.stdout
