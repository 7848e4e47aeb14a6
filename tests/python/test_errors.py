"""Bad input raises ValueError with the message `beamsim` prints for the
same command (its first line, without "beamsim: " and, for a bad option
value, the command's name before it); the program's exit status for it is
2."""

import pytest

import beamsim
from conftest import cli_message


def raises_as_cli(call, *args):
    message, status = cli_message(*args)
    assert status == 2
    command = f"{args[0]}: "
    if message.startswith(command):
        message = message[len(command):]
    with pytest.raises(ValueError) as e:
        call()
    assert str(e.value) == message


def test_group_out_of_range(h1):
    raises_as_cli(lambda: beamsim.run(h1, group=30), "run", h1, "--group", 30)
    raises_as_cli(lambda: beamsim.run(h1, trial=10**6), "run", h1, "--trial", 10**6)


def test_unknown_scene_field(gate):
    raises_as_cli(lambda: beamsim.run(gate, set={"body.mas": 2}), "run", gate, "--set",
                  "body.mas=2")
    raises_as_cli(lambda: beamsim.run(gate, set={"body.mass": -1}), "run", gate, "--set",
                  "body.mass=-1")


def test_missing_file(tmp_path):
    missing = str(tmp_path / "nothing.yaml")
    raises_as_cli(lambda: beamsim.run(missing), "run", missing)
    raises_as_cli(lambda: beamsim.sweep(missing, out=tmp_path / "o"), "sweep", missing,
                  "--out", tmp_path / "o")


def test_bad_backend_and_option(gate, h1, tmp_path):
    raises_as_cli(lambda: beamsim.run(gate, backend="box3d"), "run", gate, "--backend", "box3d")
    raises_as_cli(lambda: beamsim.sweep(h1, backend_opt={"integrator": "rk9"}), "sweep", h1,
                  "--backend-opt", "integrator=rk9", "--out", tmp_path / "o")


def test_grid_on_a_scene(gate, tmp_path):
    raises_as_cli(lambda: beamsim.run(gate, grid={"effects.propulsion.force": [6, 7]}), "run",
                  gate, "--grid", "effects.propulsion.force=6,7")
    raises_as_cli(lambda: beamsim.sweep(gate, out=tmp_path / "o"), "sweep", gate, "--out",
                  tmp_path / "o")


def test_stored_run_refuses_a_seed(h1, tmp_path):
    beamsim.sweep(h1, trials=1, out=tmp_path / "s")
    raises_as_cli(lambda: beamsim.run(tmp_path / "s", seed=3), "run", tmp_path / "s",
                  "--seed", 3)
    raises_as_cli(lambda: beamsim.run(tmp_path / "s", backend="box2d"), "run",
                  tmp_path / "s", "--backend", "box2d")


def test_trials_too_many(h1, tmp_path):
    raises_as_cli(lambda: beamsim.sweep(h1, trials=10**9), "sweep", h1, "--trials", 10**9,
                  "--out", tmp_path / "o")


def test_a_failed_call_leaves_no_directory(tmp_path, h1):
    with pytest.raises(ValueError):
        beamsim.sweep(h1, set={"body.radius": "x"}, out=tmp_path / "o")
    assert not (tmp_path / "o" / "summary.json").exists()


def test_numbers_out_of_range(gate, h1, tmp_path):
    raises_as_cli(lambda: beamsim.run(gate, seed=-1), "run", gate, "--seed", -1)
    raises_as_cli(lambda: beamsim.run(gate, stride=0), "run", gate, "--stride", 0)
    raises_as_cli(lambda: beamsim.sweep(h1, threads=0), "sweep", h1, "--threads", 0,
                  "--out", tmp_path / "o")
    raises_as_cli(lambda: beamsim.sweep(h1, trials=0), "sweep", h1, "--trials", 0,
                  "--out", tmp_path / "o")


def test_unresolvable_time_step(gate):
    """A step the model cannot resolve is refused by the library's scene
    check, as the program refuses it: on the gate, longer than the random
    force's hold 1/f = 0.02 s; at 0.02 s the trial runs, 12 s in 600 steps."""
    for dt in (0.5, 12):
        raises_as_cli(lambda: beamsim.run(gate, set={"integration.dt": dt}), "run", gate,
                      "--set", f"integration.dt={dt}")
        with pytest.raises(ValueError, match=r"integration\.dt: expected at most 0\.02 s"):
            beamsim.run(gate, set={"integration.dt": dt})
    assert beamsim.run(gate, set={"integration.dt": 0.02})["steps"] == 600


NUL = "expected text without NUL bytes"


def test_nul_in_text_is_refused(gate, h1, tmp_path):
    """Regression: a NUL inside a set value was cut there (body.mass "2\\0x"
    ran as 2). Text the library takes as a C string is refused with the
    argument named and the text escaped, wherever it holds a NUL."""
    cases = [
        (lambda: beamsim.run(gate, set={"body.mass": "2\0x"}),
         'set body.mass: the value "2\\x00x": '),
        (lambda: beamsim.run(gate, set={"body.mass\0zz": 2}),
         'set: the key "body.mass\\x00zz": '),
        (lambda: beamsim.run(gate, set=["body.mass=2\0"]), 'set body.mass: the value "2\\x00": '),
        (lambda: beamsim.sweep(h1, trials=1, grid={"body.mass": ["2\0x", 3]}),
         'grid body.mass: the value "2\\x00x": '),
        (lambda: beamsim.sweep(h1, trials=1, grid={"body.mass\0": [2, 3]}),
         'grid: the key "body.mass\\x00": '),
        (lambda: beamsim.run(gate, backend_opt={"integrator": "euler\0x"}),
         'backend_opt: the option "integrator=euler\\x00x": '),
        (lambda: beamsim.run(gate + "\0x"), 'scene "' + gate + '\\x00x": '),
        (lambda: beamsim.run(gate, backend="thesis\0"), 'backend "thesis\\x00": '),
        (lambda: beamsim.sweep(h1, out=str(tmp_path / "o\0")), 'out "'),
        (lambda: beamsim.compare(h1, backends=("thesis", "box2d\0")), 'backends "box2d\\x00": '),
        (lambda: beamsim.landscape(gate + "\0"), 'scene "'),
    ]
    for call, says in cases:
        with pytest.raises(ValueError) as e:
            call()
        assert str(e.value).startswith(says) and NUL in str(e.value), str(e.value)
    assert not (tmp_path / "o").exists()


def test_set_pair_of_the_wrong_shape(gate):
    """Regression: set=[("body.mass",)] raised "not enough values to
    unpack"; it says what set takes."""
    for bad in ([("body.mass",)], [("body.mass", 2, 3)], [7]):
        with pytest.raises(TypeError) as e:
            beamsim.run(gate, set=bad)
        assert "set: expected a dict {key: value}, \"KEY=VALUE\" strings or (key, value) " \
               "pairs, got " in str(e.value)
    # a pair as a list or tuple is one
    assert beamsim.run(gate, set=[["body.mass", 2]])["row"] == \
        beamsim.run(gate, set={"body.mass": 2})["row"]
