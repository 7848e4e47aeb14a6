"""The nearest-neighbour walks from Python: markov_build's default (the
walks' training fields), markov_predict(visits=... or map=...) and
markov_validate(visits=...) give the program's files and numbers (`beamsim
markov build`, `markov predict --visits DIR --json`, `markov validate
--visits DIR`) for the same inputs, and refuse what the program refuses."""

import json

import pytest

import beamsim
from conftest import cli, config

RING = config("markov", "kinds", "field_ring5.yaml")  # a ring of A around 3 x 3 of B
RING_EXP = config("markov", "kinds", "exp_ring5.yaml")


def test_predict_as_the_program(tmp_path):
    visits = tmp_path / "visits"
    d = beamsim.markov_predict(RING, visits=visits, train=150, walks=3000, threads=2)
    p = json.loads(cli("markov", "predict", RING, "--visits", visits, "--train", 150,
                       "--walks", 3000, "--threads", 1, "--json").stdout)
    assert d["solve"] == "nearest" and d["fields_built"] == 2 and p["fields_built"] == 0
    assert [x["p"] for x in d["locations"]] == [x["p"] for x in p["locations"]]
    assert d["totals"] == p["totals"] and d["nearest_k"] == 20
    other = beamsim.markov_predict(RING, visits=visits, train=150, walks=3000, seed=2)
    assert other["fields_built"] == 2  # the seed is the training fields' too
    assert [x["p"] for x in other["locations"]] != [x["p"] for x in d["locations"]]


def test_validate_as_the_program(tmp_path):
    visits = tmp_path / "visits"
    v = beamsim.markov_validate(RING_EXP, visits=visits, train=150, walks=2000, trials=30,
                                out=tmp_path / "a")
    cli("markov", "validate", RING_EXP, "--visits", visits, "--train", 150, "--walks", 2000,
        "--trials", 30, "--quiet", "--out", tmp_path / "b")
    w = json.loads((tmp_path / "b" / "validate.json").read_text())
    assert v["visits_dir"] == w["visits_dir"] and v["nearest_walks"] == 2000
    assert [c["tv"] for c in v["checks"]] == [c["tv"] for c in w["checks"]]


def test_refused(tmp_path):
    with pytest.raises(ValueError, match="expected one of map"):
        beamsim.markov_predict(RING)
    with pytest.raises(ValueError, match="expected one of map"):
        beamsim.markov_predict(RING, map=tmp_path, visits=tmp_path)
    with pytest.raises(ValueError, match="k: for visits only"):
        beamsim.markov_predict(RING, map=tmp_path, k=3)
    with pytest.raises(ValueError, match="--k 65"):
        beamsim.markov_predict(RING, visits=tmp_path, k=65)
    with pytest.raises(ValueError, match="tol, gates: for maps only"):
        beamsim.markov_predict(RING, visits=tmp_path, tol=0.01)
    with pytest.raises(ValueError, match="markov.json: cannot read"):
        beamsim.markov_validate(RING_EXP, map=tmp_path, walks=10)


def _files(d):
    """A build's files but for the CPU times (.cost) and the manifest."""
    return {f.name: f.read_bytes() for f in sorted(d.iterdir())
            if f.suffix != ".cost" and f.name != "manifest.json"}


def test_build_default_as_the_program(tmp_path):
    b = beamsim.markov_build(RING_EXP, tmp_path / "a", train=60, threads=2)
    cli("markov", "build", RING_EXP, "--train", 60, "--quiet", "--out", tmp_path / "b")
    assert b["method"] == "nearest" and b["built"] == 2 and b["visits"] > 0
    assert all(m["key"].startswith("visits_") for m in b["maps"])
    assert _files(tmp_path / "a") == _files(tmp_path / "b")
    d = beamsim.markov_predict(RING, map=tmp_path / "a", walks=2000, threads=2)
    p = json.loads(cli("markov", "predict", RING, "--map", tmp_path / "b", "--walks", 2000,
                       "--json").stdout)
    assert d["solve"] == "nearest" and d["fields_built"] == 0
    assert [x["p"] for x in d["locations"]] == [x["p"] for x in p["locations"]]
    m = beamsim.markov_build(RING_EXP, tmp_path / "m", bins=(1, 1, 1), trials=2,
                             start_trials=20, train=0)
    assert m["method"] == "maps" and m["maps"][0]["key"].startswith("map_")
    with pytest.raises(ValueError, match="walks: for the walks only"):
        beamsim.markov_validate(RING_EXP, map=tmp_path / "m", walks=10)
    with pytest.raises(ValueError, match="threads: for the walks only"):
        beamsim.markov_predict(RING, map=tmp_path / "m", threads=2)
    with pytest.raises(ValueError, match="bins is for method maps"):
        beamsim.markov_build(RING_EXP, tmp_path / "c", method="nearest", bins=(2, 2, 2))
    with pytest.raises(ValueError, match="k is for the nearest-neighbour walks"):
        beamsim.markov_build(RING_EXP, tmp_path / "c", method="maps", k=3)
