"""A backend written in Python, driven by the runner: a class that hands
each step to a thesis-backend World (beamsim.World) makes, through the
runner, exactly the thesis backend's sweep (every trials.csv column: the
same schedules, outcomes, energy ledger, contact flags from the impulses
it reports); the example solver (examples/python_backend.py) enters a
comparison of H1; an exception inside a step reaches the caller with the
trial it happened in; a class without the methods is refused."""

import os
import sys

import numpy as np
import pytest

import beamsim
from conftest import SRC, config

sys.path.insert(0, os.path.join(SRC, "examples"))
import python_backend  # noqa: E402


class ThesisByHand:
    """each step handed to the thesis backend's world, stepped by hand"""

    name = "thesis_by_hand"

    def __init__(self, scene):
        # H1's groups differ in their forces only: the gate's bodies and
        # beams are gate.yaml's, whose world steps under the forces given
        assert scene["body"]["mass"] == 1.0 and len(scene["beams"]) == 2
        self.w = beamsim.World(config("thesis", "gate.yaml"), backend="thesis")

    def advance(self, force, torque, h):
        assert h == self.w.dt
        self.w.step(force, torque=torque)

    def state(self):
        return self.w.state


def test_runner_drives_it_as_its_own():
    h1 = config("thesis", "h1_symmetric.yaml")
    mine = beamsim.sweep(h1, backend=ThesisByHand, trials=3, threads=2)
    theirs = beamsim.sweep(h1, backend="thesis", trials=3, threads=1)
    a, b = mine["trials"], theirs["trials"]
    assert list(a) == list(b)
    for column in a:
        nan = a[column].dtype.kind == "f"  # overlap_max: NaN, not measured
        assert np.array_equal(a[column], b[column], equal_nan=nan), column
    assert "thesis_by_hand" in beamsim.backends()


def test_example_enters_a_comparison():
    r = beamsim.compare(config("thesis", "h1_symmetric.yaml"),
                        backends=["thesis", python_backend.GateEulerPy], trials=3)
    assert list(r["sides"]) == ["thesis", "gate_euler_py"]
    g = r["sides"]["gate_euler_py"]["trials"]
    assert len(g["outcome"]) == len(r["sides"]["thesis"]["trials"]["outcome"]) == 30 * 3
    assert set(g["outcome"]) <= {"traversed", "side_exit", "stuck"}


class FailsAtStep:
    name = "fails_at_step"

    def __init__(self, scene):
        self.n = 0
        self.s = {"x": scene["body"]["start"], "v": (0.0, 0.0), "theta": (0.0, 0.0),
                  "omega": (0.0, 0.0)}

    def advance(self, force, torque, h):
        self.n += 1
        if self.n == 40:
            raise ZeroDivisionError("the solver's own bug")

    def state(self):
        return self.s


def test_exception_names_the_trial():
    with pytest.raises(RuntimeError) as e:
        beamsim.sweep(config("thesis", "h1_symmetric.yaml"), backend=FailsAtStep, trials=1,
                      threads=1)
    msg = str(e.value)
    assert "group 0, trial 0" in msg and "advance raised ZeroDivisionError: the solver's own " \
        "bug" in msg, msg


def test_a_class_without_the_methods():
    class NoState:
        def advance(self, force, torque, h):
            pass

    with pytest.raises(TypeError, match="advance.*state"):
        beamsim.sweep(config("thesis", "h1_symmetric.yaml"), backend=NoState, trials=1)
