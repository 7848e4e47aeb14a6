"""beamsim.compare with a side read from a trials.csv made elsewhere
(backends=[..., "trials:PATH"]) against `beamsim compare --backends
...,trials:PATH`: the same files, the side by its spec; a file that does not
fit the experiment is a ValueError naming file, line and field."""

import filecmp
import json

import pytest

import beamsim
from conftest import cli
from test_sweep import without_wall


def test_compare_reads_a_side(h1, tmp_path):
    cli("sweep", h1, "--trials", 2, "--threads", 2, "--out", tmp_path / "made")
    side = f"trials:{tmp_path / 'made'}"
    cli("compare", h1, "--trials", 2, "--threads", 2, "--backends", f"thesis,{side}",
        "--out", tmp_path / "cli")
    c = beamsim.compare(h1, backends=["thesis", side], trials=2, out=tmp_path / "py")
    for name in ("pairs.csv", "thesis/trials.csv", "made/trials.csv", "made/summary.json"):
        assert filecmp.cmp(tmp_path / "cli" / name, tmp_path / "py" / name, shallow=False)
    assert filecmp.cmp(tmp_path / "made" / "trials.csv", tmp_path / "py" / "made" / "trials.csv",
                       shallow=False)
    with open(tmp_path / "cli" / "report.json") as f:
        report = json.load(f)
    assert without_wall(c["report"]) == without_wall(report)
    assert tuple(c["sides"]) == ("thesis", side)
    assert c["report"]["b"]["read_from"] == str((tmp_path / "made" / "trials.csv").resolve())
    assert c["n_disagree"] == 0
    with pytest.raises(ValueError, match=r"made/trials.csv:61: expected 90 rows"):
        beamsim.compare(h1, backends=["thesis", side], trials=3, out=tmp_path / "refused")
    assert not (tmp_path / "refused").exists()
