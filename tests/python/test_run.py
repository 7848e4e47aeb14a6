"""beamsim.run against `beamsim run --json` and `--trajectory` for the same
trial: a scene, an experiment's group, overrides, the other backend."""

import numpy as np
import pytest

import beamsim
from conftest import cli, cli_json, config


def same_as_cli(r, c):
    """Every field of run --json is in the module's dict with the same value
    (JSON numbers are written to 17 digits, so equal means bit-equal)."""
    for key, value in c.items():
        assert r[key] == value, key


def test_scene_trial_is_the_cli_trial(gate):
    r = beamsim.run(gate, seed=3, group=1, trial=2)
    same_as_cli(r, cli_json("run", gate, "--seed", 3, "--group", 1, "--trial", 2))
    assert "grid" not in r


def test_experiment_group_is_the_sweep_trial(h1):
    r = beamsim.run(h1, group=17, trial=4)
    same_as_cli(r, cli_json("run", h1, "--group", 17, "--trial", 4))
    text = cli("run", h1, "--group", 17, "--trial", 4).stdout
    assert f"grid        {r['grid']}\n" in text
    assert f"row         {r['row']} " in text


def test_overrides_and_backend_options(gate):
    sets = {"effects.propulsion.force": 8.5, "beams.0.stiffness": 250}
    r = beamsim.run(gate, seed=2, backend="box2d", set=sets, backend_opt={"substeps": 2})
    c = cli_json("run", gate, "--seed", 2, "--backend", "box2d", "--set",
                 "effects.propulsion.force=8.5", "--set", "beams.0.stiffness=250",
                 "--backend-opt", "substeps=2")
    same_as_cli(r, c)
    assert r["backend"] == "box2d"
    # The overrides reached the scene: the plain scene's trial is another.
    assert beamsim.run(gate, seed=2, backend="box2d")["ledger"] != r["ledger"]


def check_trajectory_csv(scene, tmp_path, *backend):
    """The arrays written as the CLI writes trajectory.csv (t as %.6f, the
    contact flags as integers, the rest as %.10g) are its bytes."""
    out = tmp_path / "traj.csv"
    cli("run", scene, "--seed", 5, "--trajectory", out, "--stride", 7, *backend)
    kw = {"backend": backend[1]} if backend else {}
    r = beamsim.run(scene, seed=5, trajectory=True, stride=7, **kw)
    tr = r["trajectory"]
    lines = out.read_text().splitlines()
    header = lines[0].split(",")
    assert list(tr) == header
    assert all(len(tr[c]) == len(lines) - 1 for c in header)
    assert tr["contact1"].dtype == np.int32 and tr["y"].dtype == np.float64

    def fmt(name, v):
        if name == "t":
            return "%.6f" % v
        if name.startswith("contact"):
            return "%d" % v
        return "%.10g" % v

    for i, line in enumerate(lines[1:]):
        assert ",".join(fmt(c, tr[c][i]) for c in header) == line, i
    # Rows at t = 0, after every stride-th step and after the last one.
    n = r["steps_run"]
    assert len(tr["t"]) == n // 7 + 1 + (n % 7 != 0)
    return header


def test_trajectory_columns_are_trajectory_csv(gate, tmp_path):
    header = check_trajectory_csv(gate, tmp_path)
    assert header[-1] == "e_prop"


def test_turning_body_has_its_columns(tmp_path):
    """A capsule that turns (Box2D): the trajectory ends with heading and
    angular_velocity, in the module as in the CSV; the result's turn
    (heading_end, angular_velocity_end, turn_end, turn_max) is run --json's."""
    scene = tmp_path / "capsule.yaml"
    text = open(config("thesis", "gate.yaml")).read()
    text = text.replace("body:      { mass: 1.0, radius: 10.0,",
                        "body:      { mass: 1.0, radius: 6.0, shape: capsule, length: 10,")
    assert "capsule" in text
    scene.write_text(text)
    header = check_trajectory_csv(scene, tmp_path, "--backend", "box2d")
    assert header[-2:] == ["heading", "angular_velocity"]
    # How far it turned: run --json's numbers, and a turn.
    r = beamsim.run(scene, backend="box2d")
    same_as_cli(r, cli_json("run", scene, "--backend", "box2d"))
    assert r["turn_max"] > 0.01 and r["turn_max"] >= abs(r["turn_end"])


def test_no_trajectory_unless_asked(gate):
    assert "trajectory" not in beamsim.run(gate)


def test_unstable_trial_is_said():
    """The stiff beam on Box2D's explicit spring torque blows up: the
    program exits 1 with a line; the module returns the trial, outcome
    unstable, and warns with the same line."""
    scene = config("hard", "stiff_beam.yaml")
    args = ("run", scene, "--backend", "box2d", "--backend-opt", "spring=torque")
    p = cli(*args, check=False)
    assert p.returncode == 1
    line = next(s for s in p.stderr.splitlines() if "unstable trial" in s)
    with pytest.warns(RuntimeWarning) as w:
        r = beamsim.run(scene, backend="box2d", backend_opt={"spring": "torque"})
    assert r["outcome"] == "unstable" and r["instability"] is not None
    assert [str(x.message) for x in w] == [line[len("beamsim: "):]]
