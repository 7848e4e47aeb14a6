"""beamsim.sweep, compare and load against `beamsim sweep` and `beamsim
compare` on the same experiment, trials and seed: the same trials.csv bytes,
the same groups, whatever the threads; a trial of the sweep replayed."""

import filecmp
import json

import numpy as np
import pytest

import beamsim
from conftest import cli


def without_wall(d):
    """d without its wall times (at any depth), which no two runs share."""
    if isinstance(d, dict):
        return {k: without_wall(v) for k, v in d.items() if "seconds" not in k}
    if isinstance(d, list):
        return [without_wall(v) for v in d]
    return d


def same_arrays(a, b):
    assert list(a) == list(b)
    for k in a:
        assert a[k].dtype == b[k].dtype, k
        if a[k].dtype.kind == "f":
            assert np.array_equal(a[k], b[k], equal_nan=True), k
        else:
            assert np.array_equal(a[k], b[k]), k


def test_sweep_is_the_cli_sweep(h1, tmp_path):
    cli("sweep", h1, "--trials", 4, "--seed", 9, "--threads", 2, "--out", tmp_path / "cli")
    s = beamsim.sweep(h1, trials=4, seed=9, threads=1, out=tmp_path / "py")
    assert filecmp.cmp(tmp_path / "cli" / "trials.csv", tmp_path / "py" / "trials.csv",
                       shallow=False)
    c = beamsim.load(tmp_path / "cli")
    same_arrays(s["trials"], c["trials"])
    assert s["groups"] == c["summary"]["groups"]
    assert without_wall(s["summary"]) == without_wall(c["summary"])
    assert len(s["groups"]) == 30 and len(s["trials"]["outcome"]) == 30 * 4
    # In a temporary directory: the same numbers, nothing kept.
    t = beamsim.sweep(h1, trials=4, seed=9, threads=2)
    same_arrays(t["trials"], s["trials"])
    assert t["out"] is None


def test_grid_and_set(h1, tmp_path):
    grid = {"effects.propulsion.force": [6, 7.5]}
    sets = {"beams.0.stiffness": 300}
    cli("sweep", h1, "--trials", 3, "--grid", "effects.propulsion.force=6,7.5", "--set",
        "beams.0.stiffness=300", "--out", tmp_path / "cli")
    s = beamsim.sweep(h1, trials=3, grid=grid, set=sets)
    c = beamsim.load(tmp_path / "cli")
    same_arrays(s["trials"], c["trials"])
    assert s["groups"] == c["summary"]["groups"]
    assert {g["params"]["effects.propulsion.force"] for g in s["groups"]} == {6, 7.5}
    assert set(s["trials"]["effects.propulsion.force"]) == {6, 7.5}


def test_kept_trajectories(h1, tmp_path):
    cli("sweep", h1, "--trials", 2, "--trajectories", 1, "--out", tmp_path / "cli")
    r = beamsim.sweep(h1, trials=2, trajectories=1, out=tmp_path / "py")
    assert filecmp.cmp(tmp_path / "cli" / "trajectories.csv",
                       tmp_path / "py" / "trajectories.csv", shallow=False)
    # by trial, with or without out: each kept trial's rows of the file, in order
    table = beamsim.read_csv(tmp_path / "cli" / "trajectories.csv")
    for got in (r["trajectories"], beamsim.sweep(h1, trials=2, trajectories=1)["trajectories"]):
        assert sorted(got) == [(g, 0) for g in range(30)]
        for (g, t), cols in got.items():
            rows = (table["group"] == g) & (table["trial"] == t)
            assert set(cols) == set(table) - {"group", "trial"}
            for c, v in cols.items():
                assert v.shape == (rows.sum(),) and np.array_equal(v, table[c][rows]), (g, c)
    assert beamsim.sweep(h1, trials=2)["trajectories"] == {}


def test_stored_sweep_replays(h1, tmp_path):
    s = beamsim.sweep(h1, trials=3, out=tmp_path / "s")
    tr = s["trials"]
    for k in (5, 47, 88):
        g, t = int(tr["group"][k]), int(tr["trial"][k])
        r = beamsim.run(tmp_path / "s", group=g, trial=t)
        assert r["stored_row"] == r["row"]
        assert r["outcome"] == tr["outcome"][k] and r["steps"] == tr["steps"][k]
        for f in ("x_end", "heading_end", "angular_velocity_end", "turn_end", "turn_max"):
            assert "%.10g" % r[f] == "%.10g" % tr[f][k]


def test_compare_is_the_cli_compare(h1, tmp_path):
    # exit 3 if a group disagrees (Box2D's float32 may tip the symmetric
    # gate's deterministic traversal to a side, docs/compare.md)
    p = cli("compare", h1, "--trials", 2, "--threads", 2, "--out", tmp_path / "cli",
            check=False)
    c = beamsim.compare(h1, trials=2, out=tmp_path / "py")
    assert p.returncode == (3 if c["n_disagree"] else 0), p.stderr
    for name in ("pairs.csv", "thesis/trials.csv", "box2d/trials.csv"):
        assert filecmp.cmp(tmp_path / "cli" / name, tmp_path / "py" / name, shallow=False)
    with open(tmp_path / "cli" / "report.json") as f:
        report = json.load(f)
    assert without_wall(c["report"]) == without_wall(report)
    assert set(c["sides"]) == {"thesis", "box2d"}
    assert c["sides"]["box2d"]["trials"]["outcome"].shape == (60,)
    # A side's trial replayed from the comparison's directory.
    for side in ("thesis", "box2d"):
        r = beamsim.run(tmp_path / "py", group=29, trial=1, backend=side)
        assert r["backend"] == side and r["stored_row"] == r["row"]


def test_compare_three_sides_is_the_cli_compare(h1, tmp_path):
    """compare(backends=...) of three sides: the program's files, the sides by
    label in the order given, report.json's sides, pairwise and odd ones out."""
    sides = ("thesis", "thesis:integrator=euler", "box2d")
    p = cli("compare", h1, "--trials", 2, "--threads", 2, "--backends", ",".join(sides),
            "--out", tmp_path / "cli", check=False)
    c = beamsim.compare(h1, backends=sides, trials=2, out=tmp_path / "py")
    assert p.returncode == (3 if c["n_disagree"] else 0), p.stderr
    for name in ("pairs.csv", "thesis/trials.csv", "thesis-integrator=euler/trials.csv",
                 "box2d/trials.csv"):
        assert filecmp.cmp(tmp_path / "cli" / name, tmp_path / "py" / name, shallow=False)
    with open(tmp_path / "cli" / "report.json") as f:
        report = json.load(f)
    assert without_wall(c["report"]) == without_wall(report)
    assert tuple(c["sides"]) == sides
    assert [s["label"] for s in c["report"]["sides"]] == list(sides)
    assert len(c["report"]["groups"][0]["pairwise"]) == 3
    assert c["n_disagree"] == c["report"]["groups_disagreeing"]
    assert list(c["pairs"])[:8] == ["group", "trial", "outcome_a", "type_a", "outcome_b",
                                    "type_b", "outcome_c", "type_c"]
    with pytest.raises(ValueError, match="expected 2 to 8"):
        beamsim.compare(h1, backends=("thesis",), trials=1)


def test_load_reads_run_out(gate, tmp_path):
    """run --out's directory read back by load; the module's trajectory and
    ledger rows printed as the program prints them are its trajectory.csv
    and ledger.csv."""
    cli("run", gate, "--seed", 4, "--stride", 3, "--out", tmp_path / "r")
    d = beamsim.load(tmp_path / "r")
    r = beamsim.run(gate, seed=4, trajectory=True, stride=3)
    assert d["run"]["outcome"] == r["outcome"]
    for name, mine in (("trajectory", r["trajectory"]), ("ledger", r["ledger_rows"])):
        lines = (tmp_path / "r" / f"{name}.csv").read_text().splitlines()
        assert lines[0].split(",") == list(mine) == list(d[name])
        for i, line in enumerate(lines[1:]):
            text = ["%.6f" % v if c == "t" else "%d" % v if c.startswith("contact") and
                    name == "trajectory" else "%.10g" % v for c, v in
                    ((c, mine[c][i]) for c in mine)]
            assert ",".join(text) == line, (name, i)
