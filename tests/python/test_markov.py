"""beamsim.markov_build, markov_predict and markov_validate against the
program's `beamsim markov build`, `predict --json` and `validate` for the
same inputs: the same maps byte for byte, the same prediction and the same
validation (but for the times measured), and the program's refusals.
Small maps (3 single gates a bin, 2 x 2 x 1 bins) on the C-track, so that
the whole file takes about a second."""

import json
import os

import pytest

import beamsim
from conftest import cli, cli_message, config

EXPERIMENT = config("markov", "c_track.yaml")
SCENE = config("lattice", "c_track.yaml")
SMALL = dict(trials=3, bins=(2, 2, 1), threads=2, start_trials=7, train=40)
SMALL_ARGS = ["--trials", "3", "--bins", "2,2,1", "--threads", "2", "--start-trials", "7",
              "--train", "40"]
# what two runs of one prediction or validation measure differently
TIMES = ("predict_seconds", "predict_cpu_seconds", "sim_cpu_seconds", "speedup",
         "break_even_lattices", "map_cpu_seconds")


def untimed(d):
    """d without the times measured (recursively)."""
    if isinstance(d, dict):
        return {k: untimed(v) for k, v in d.items() if k not in TIMES}
    if isinstance(d, list):
        return [untimed(v) for v in d]
    return d


def map_files(d):
    """The map directory's files but for the CPU times (.cost) and the
    manifest, which lists their sizes: {name: bytes}."""
    out = {}
    for name in sorted(os.listdir(d)):
        if name.endswith(".cost") or name == "manifest.json" or name.startswith("."):
            continue
        with open(os.path.join(d, name), "rb") as f:
            out[name] = f.read()
    return out


@pytest.fixture(scope="module")
def maps(tmp_path_factory):
    """The same maps built by the module and by the program."""
    tmp = tmp_path_factory.mktemp("markov")
    py, prog = tmp / "py", tmp / "prog"
    built = beamsim.markov_build(EXPERIMENT, py, seed=5, **SMALL)
    cli("markov", "build", EXPERIMENT, *SMALL_ARGS, "--seed", "5", "--out", prog)
    return built, str(py), str(prog), tmp


def test_build_is_the_programs(maps):
    built, py, prog, _ = maps
    # the maps the program lists, each with its key, in order
    run = cli("markov", "build", EXPERIMENT, *SMALL_ARGS, "--seed", "5", "--out", prog)
    lines = run.stdout.splitlines()
    # the program's note on these coarse bins and few start trials
    assert built["scope"].startswith("maps with 40 training trials (the default 4000), 2,2,1 "
                                     "bins (the default 14,6,13), 7 start")
    assert f"note: {built['scope']}" in run.stderr
    listed = [line.split()[-2] for line in lines if line.startswith("group ")]
    assert [m["key"] for m in built["maps"]] == listed
    assert built["built"] == len(built["maps"]) and built["reused"] == 0
    assert built["bins"] == 1 + 4 * 2 * 2 * 1 and built["trials"] == 3
    # the same maps, byte for byte (not the CPU time each took), the gates
    # after the start among them
    assert map_files(py) == map_files(prog)
    assert any(".after_" in name for name in map_files(py))
    # a build again reuses every map
    again = beamsim.markov_build(EXPERIMENT, py, seed=5, **SMALL)
    assert again["reused"] == len(built["maps"]) and again["built"] == 0


def test_after_start_is_the_programs(tmp_path):
    """after_start=False builds what --after-start 0 builds: no gate after
    the start."""
    py, prog = tmp_path / "py", tmp_path / "prog"
    beamsim.markov_build(EXPERIMENT, py, seed=5, after_start=False, **SMALL)
    cli("markov", "build", EXPERIMENT, *SMALL_ARGS, "--seed", "5", "--after-start", "0",
        "--out", prog)
    assert map_files(py) == map_files(prog)
    assert not any(".after_" in name for name in map_files(py))


def test_after_trials_is_the_programs(tmp_path):
    """after_trials=3 builds what --after-trials 3 builds: the first 3 of
    the 7 start trials continued, in files of their own."""
    py, prog = tmp_path / "py", tmp_path / "prog"
    beamsim.markov_build(EXPERIMENT, py, seed=5, after_trials=3, **SMALL)
    cli("markov", "build", EXPERIMENT, *SMALL_ARGS, "--seed", "5", "--after-trials", "3",
        "--out", prog)
    assert map_files(py) == map_files(prog)
    assert any(name.endswith(".first3.csv") for name in map_files(py))


@pytest.mark.parametrize("arg, option, entries", [
    (dict(crossings=False), ["--crossings", "0"], b"entries train 40 kinds "),
    (dict(per_crossing=1), ["--per-crossing", "1"], b"entries train 40 crossings per 1 kinds "),
])
def test_crossings_is_the_programs(tmp_path, arg, option, entries):
    """crossings=False builds what --crossings 0 builds (bins of single
    gates alone), per_crossing=1 what --per-crossing 1 builds (bins counted
    from the training field's crossings, topped up to 1 single gate a
    crossing)."""
    py, prog = tmp_path / "py", tmp_path / "prog"
    beamsim.markov_build(EXPERIMENT, py, seed=5, **arg, **SMALL)
    cli("markov", "build", EXPERIMENT, *SMALL_ARGS, "--seed", "5", *option, "--out", prog)
    files = map_files(py)
    assert files == map_files(prog)
    keys = [text for name, text in files.items() if name.endswith(".key")]
    assert keys and all(entries in text for text in keys)


def test_predict_is_the_programs(maps):
    _, py, prog, tmp = maps
    for walks in (None, 0, 500):
        args = [] if walks is None else ["--walks", str(walks)]
        want = json.loads(cli("markov", "predict", SCENE, "--map", prog, "--json",
                              *args).stdout)
        got = beamsim.markov_predict(SCENE, py, walks=walks)
        assert untimed({k: got[k] for k in want}) == untimed(want)
        assert set(got) - set(want) == {"p_time", "time_bin", "p_loc_time"}
        if want.get("walks"):
            # the outcome's time bins sum to the walks' totals at the duration
            kinds = ("end", "side", "stuck")
            for k, kind in enumerate(kinds):
                assert got["p_time"][:, k].sum() == pytest.approx(
                    want["at_duration"][kind]["p"], abs=1e-12)
        else:
            assert got["p_time"].shape == (0, 3)
    # the series with the distribution of gates visited, a tolerance of its own
    want = json.loads(cli("markov", "predict", SCENE, "--map", prog, "--json", "--gates",
                          "--tol", "1e-9").stdout)
    got = beamsim.markov_predict(SCENE, py, gates=True, tol=1e-9)
    assert untimed({k: got[k] for k in want}) == untimed(want)
    assert len(got["p_gates"]) > 1
    # out: the program's files
    cli("markov", "predict", SCENE, "--map", prog, "--out", tmp / "pred_prog")
    beamsim.markov_predict(SCENE, py, out=tmp / "pred_py")
    for name in ("prediction.csv", "prediction_gates.csv", "time.csv"):
        with open(tmp / "pred_py" / name, "rb") as a, open(tmp / "pred_prog" / name, "rb") as b:
            assert a.read() == b.read(), name


def test_validate_is_the_programs(maps):
    _, py, prog, tmp = maps
    args = ["--trials", "12", "--bootstrap", "30", "--threads", "2"]
    cli("markov", "validate", EXPERIMENT, "--map", prog, *args, "--out", tmp / "val_prog")
    got = beamsim.markov_validate(EXPERIMENT, py, trials=12, bootstrap=30, threads=2,
                                  out=tmp / "val_py")
    with open(tmp / "val_prog" / "validate.json", encoding="utf-8") as f:
        want = json.load(f)
    del want["map_dir"], got["map_dir"]
    assert untimed({k: got[k] for k in want}) == untimed(want)
    assert [c["protocol"] for c in got["checks"]] == ["essay", "world"]
    assert got["maps_scope"].startswith("maps with 40 training trials (the default 4000), "
                                        "2,2,1 bins (the default 14,6,13)")
    # maps of the default method: bins counted from the crossings, 5 a crossing
    assert (got["of_crossings"], got["per_crossing"]) == (1, 5)
    with open(tmp / "val_prog" / "validate.csv", "rb") as f:
        assert (tmp / "val_py" / "validate.csv").read_bytes() == f.read()
    assert list(got["files"]["validate"]["p_sim"]) == list(
        beamsim.read_csv(tmp / "val_prog" / "validate.csv")["p_sim"])
    # a finished validation is refused without overwrite, in the module's words
    with pytest.raises(ValueError, match="overwrite=True") as e:
        beamsim.markov_validate(EXPERIMENT, py, trials=12, bootstrap=30, out=tmp / "val_py")
    assert "--overwrite" not in str(e.value)


def test_bad_arguments(maps, tmp_path):
    _, py, prog, _ = maps
    # the library's refusals are the program's, word for word
    target = tmp_path / "maps"
    msg, status = cli_message("markov", "build", config("thesis", "h1_symmetric.yaml"),
                              "--out", target)
    assert status == 2
    with pytest.raises(ValueError) as e:
        beamsim.markov_build(config("thesis", "h1_symmetric.yaml"), target)
    assert str(e.value) == msg and "not a gate lattice" in msg
    missing = tmp_path / "none"
    msg, status = cli_message("markov", "predict", SCENE, "--map", missing)
    assert status == 2
    with pytest.raises(ValueError) as e:
        beamsim.markov_predict(SCENE, missing)
    assert str(e.value) == msg
    # the module's own checks, naming the argument
    with pytest.raises(ValueError, match=r"--bins \(2, 0, 1\): expected P,S,D"):
        beamsim.markov_build(EXPERIMENT, target, bins=(2, 0, 1))
    with pytest.raises(ValueError, match="entries self:9: expected self, self:N"):
        beamsim.markov_build(EXPERIMENT, target, entries="self:9")
    with pytest.raises(ValueError, match=r"--train -1: expected an integer >= 0"):
        beamsim.markov_build(EXPERIMENT, target, train=-1)
    with pytest.raises(ValueError, match=r"--tol 2: expected the probability"):
        beamsim.markov_predict(SCENE, py, tol=2)
    with pytest.raises(ValueError, match=r"--walks -1: expected an integer"):
        beamsim.markov_predict(SCENE, py, walks=-1)
    assert not target.exists()
    # a finished prediction is refused without overwrite, in the module's words
    out = tmp_path / "pred"
    beamsim.markov_predict(SCENE, py, walks=0, out=out)
    with pytest.raises(ValueError, match="overwrite=True"):
        beamsim.markov_predict(SCENE, py, walks=0, out=out)
    beamsim.markov_predict(SCENE, py, walks=0, out=out, overwrite=True)
