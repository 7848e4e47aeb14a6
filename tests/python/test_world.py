"""beamsim.World, a world stepped by hand, on every backend: under the
scene's effects it makes a trial's steps as beamsim.run makes them, state
for state to the bit (the trajectory's columns, doubles as the library
holds them); from a stored sweep's directory, that sweep's trial; a held
force on a free body gives it the impulse's velocity; reset starts again;
bad arguments are refused naming them."""

import numpy as np
import pytest

import beamsim
from conftest import config


@pytest.mark.parametrize("backend", beamsim.backends())
def test_steps_are_the_trial(backend):
    h1 = config("thesis", "h1_symmetric.yaml")
    r = beamsim.run(h1, group=20, trial=3, backend=backend, trajectory=True)
    tr = r["trajectory"]
    w = beamsim.World(h1, group=20, trial=3, backend=backend)
    assert w.backend == backend
    assert w.state["step"] == 0 and w.state["x"][1] == tr["y"][0]
    n = len(tr["t"]) - 1  # a row at t = 0, then one a step
    for k in range(1, n + 1):
        w.step()
        s = w.state
        assert s["step"] == k and s["t"] == tr["t"][k]
        assert (s["x"][0], s["x"][1], s["v"][0], s["v"][1]) == \
            (tr["x"][k], tr["y"][k], tr["vx"][k], tr["vy"][k]), k
        assert (s["theta"][0], s["omega"][1]) == (tr["theta1"][k], tr["omega2"][k]), k
        assert (s["contact"][0], s["contact"][1]) == (tr["contact1"][k], tr["contact2"][k]), k
        assert s["force"][0] == tr["f_rand"][k]
    assert (w.state["x"][0], w.state["x"][1]) == (r["x_end"], r["y_end"])
    # again from the start, all the steps in one call
    w.reset()
    assert w.state["step"] == 0
    w.step(n=n)
    assert (w.state["x"][0], w.state["x"][1]) == (r["x_end"], r["y_end"])


def test_stored_sweep_trial(tmp_path):
    out = tmp_path / "h1"
    beamsim.sweep(config("thesis", "h1_symmetric.yaml"), trials=3, out=out)
    r = beamsim.run(out, group=11, trial=2, trajectory=True)
    tr = r["trajectory"]
    w = beamsim.World(out, group=11, trial=2)
    w.step(n=len(tr["t"]) - 1)
    s = w.state
    assert (s["x"][0], s["x"][1], s["v"][0]) == (r["x_end"], r["y_end"], r["vx_end"])
    assert (s["x"][0], s["x"][1]) == (tr["x"][-1], tr["y"][-1])


@pytest.mark.parametrize("backend", beamsim.backends())
def test_held_force_is_the_impulse(backend):
    gate = config("thesis", "gate.yaml")
    w = beamsim.World(gate, backend=backend,
                      set={"body.start": "[500, 0]", "effects.propulsion.force": 0,
                           "effects.random_force.magnitude": 0})
    f, n, m = (-3.0, 7.0), 250, 1.0
    w.step(f, n=n)
    s = w.state
    want = np.array(f) * n * w.dt / m
    assert np.allclose(s["v"], want, rtol=1e-5, atol=0)  # float32 on Box2D
    assert tuple(s["force"]) == (f[0], f[1], 0.0)
    assert s["contact"].dtype == np.int32 and not s["contact"].any()
    assert s["e_kin"] == pytest.approx(0.5 * m * float(s["v"] @ s["v"]), rel=1e-12)


def test_bad_arguments():
    gate = config("thesis", "gate.yaml")
    w = beamsim.World(gate)
    with pytest.raises(ValueError, match="n 0: expected an integer >= 1"):
        w.step(n=0)
    with pytest.raises(ValueError, match=r"force \(1.0,\): expected \(F_x, F_y\)"):
        w.step((1,))
    with pytest.raises(ValueError, match="unknown backend"):
        beamsim.World(gate, backend="no_such_engine")
    with pytest.raises(ValueError, match="--group 30"):
        beamsim.World(config("thesis", "h1_symmetric.yaml"), group=30)
