"""scripts/markov_nearest.py against direct simulation: the nearest-neighbour
walks over training fields' visits predict a field's final locations as its
own trials under the essay's protocol give them."""

import csv
import math
import os
import subprocess
import sys

from conftest import EXE, SRC, cli, config

SCRIPT = os.path.join(SRC, "scripts", "markov_nearest.py")
RING = config("markov", "kinds", "field_ring5.yaml")  # a ring of A around 3 x 3 of B


def nearest(*args):
    return subprocess.run([sys.executable, SCRIPT, *map(str, args), "--exe", EXE],
                          capture_output=True, text=True)


def read(path, key, value):
    with open(path, newline="") as f:
        return {r[key]: r[value] for r in csv.DictReader(f)}


def test_walks_against_direct_simulation(tmp_path):
    n_sim, n_walks = 2000, 20000
    cli("sweep", config("markov", "kinds", "exp_ring5.yaml"), "--trials", n_sim,
        "--set", "lattice.protocol=essay", "--threads", 2, "--quiet", "--out", tmp_path / "sim")
    sim = {}
    for loc in read(tmp_path / "sim" / "trials.csv", "trial", "location").values():
        sim[loc] = sim.get(loc, 0) + 1 / n_sim
    p = nearest(RING, "--out", tmp_path / "nn", "--trials", 1000, "--walks", n_walks,
                "--threads", 2)
    assert p.returncode == 0, p.stderr
    nn = {k: float(v) for k, v in read(tmp_path / "nn" / "prediction.csv", "location",
                                      "p").items()}
    assert abs(sum(nn.values()) - 1) < 1e-9
    # every location within 4.5 standard errors of the two samples
    for loc in set(sim) | set(nn):
        a, b = sim.get(loc, 0.0), nn.get(loc, 0.0)
        q = max(a, b, 1.0 / n_sim)
        se = math.sqrt(q * (1 - q) / n_sim + q * (1 - q) / n_walks)
        assert abs(a - b) <= 4.5 * se, (loc, a, b, se)
    assert len(sim) > 5


def test_same_seed_same_walks_and_training_reused(tmp_path):
    args = (RING, "--train", tmp_path / "train", "--trials", 200, "--walks", 3000,
            "--threads", 2)
    p1 = nearest(*args, "--out", tmp_path / "a")
    assert p1.returncode == 0, p1.stderr
    made = os.path.getmtime(tmp_path / "train" / "train_0" / "cpu_seconds")
    p2 = nearest(*args, "--out", tmp_path / "b")
    assert p2.returncode == 0, p2.stderr
    assert os.path.getmtime(tmp_path / "train" / "train_0" / "cpu_seconds") == made
    a = (tmp_path / "a" / "prediction.csv").read_bytes()
    assert a == (tmp_path / "b" / "prediction.csv").read_bytes()
    p3 = nearest(*args, "--out", tmp_path / "c", "--seed", 2)
    assert p3.returncode == 0, p3.stderr
    assert (tmp_path / "c" / "prediction.csv").read_bytes() != a


def test_bad_input_exits_2_naming_it(tmp_path):
    p = nearest(RING, "--out", tmp_path / "x", "--k", 0)
    assert p.returncode == 2 and "--k: expected an integer >= 1, got 0" in p.stderr
    scene = tmp_path / "no_lattice.yaml"
    scene.write_text("name: x\nbody: { mass: 1.0, radius: 10.0 }\n")
    p = nearest(scene, "--out", tmp_path / "y")
    assert p.returncode == 2 and "no_lattice.yaml: stiffness_left" in p.stderr
    p = nearest(RING, "--out", tmp_path / "z", "--validate", tmp_path / "missing")
    assert p.returncode == 2 and "no validate.csv" in p.stderr
    assert not (tmp_path / "z" / "prediction.csv").exists()
