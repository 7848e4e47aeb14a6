"""beamsim.plot: the figures draw the result's own numbers (matplotlib's
Agg, no display): p_traverse's points and Wilson bars are summary.json's
p_traverse and ci95, one line per value of the other axis; the kept paths
are the sweep's trajectories; a run's contact points are its flagged rows;
what cannot be drawn is refused naming what is missing."""

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import beamsim  # noqa: E402
import beamsim.plot  # noqa: E402
from conftest import config  # noqa: E402


@pytest.fixture(scope="module")
def h1_sweep():
    return beamsim.sweep(config("thesis", "h1_symmetric.yaml"), trials=4, trajectories=1)


def test_p_traverse_draws_the_summary(h1_sweep):
    ax = beamsim.plot.p_traverse(h1_sweep)
    groups = h1_sweep["groups"]
    key = "effects.propulsion.force"
    assert ax.get_xlabel() == key
    lines = ax.get_lines()
    rms = sorted({g["params"]["effects.random_force.magnitude"] for g in groups})
    data = [l for l in lines if len(l.get_xdata()) > 1 and l.get_marker() == "o"]
    assert len(data) == len(rms)
    for line, rm in zip(data, rms):
        mine = [g for g in groups if g["params"]["effects.random_force.magnitude"] == rm]
        assert list(line.get_xdata()) == [g["params"][key] for g in mine]
        assert list(line.get_ydata()) == [g["p_traverse"] for g in mine]
    # the bars: each point's (lo, hi) segment is its ci95
    segs = [s for c in ax.collections for s in c.get_segments()]
    want = sorted((float(g["params"][key]), g["ci95"][0], g["ci95"][1]) for g in groups)
    got = sorted((s[0][0], s[0][1], s[1][1]) for s in segs)
    assert np.allclose(got, want)
    with pytest.raises(ValueError, match="expected one of the grid's keys"):
        beamsim.plot.p_traverse(h1_sweep, x="body.mass")


def test_trajectories_are_the_kept_ones(h1_sweep):
    ax = beamsim.plot.trajectories(h1_sweep, groups=[3, 27])
    kept = h1_sweep["trajectories"]
    lines = ax.get_lines()
    assert len(lines) == 2
    for line, key in zip(lines, [(3, 0), (27, 0)]):
        assert np.array_equal(line.get_xdata(), kept[key]["x"])
        assert np.array_equal(line.get_ydata(), kept[key]["y"])
    with pytest.raises(ValueError, match="kept none"):
        beamsim.plot.trajectories(beamsim.sweep(config("thesis", "h1_symmetric.yaml"),
                                                trials=1))


def test_run_contact_points():
    r = beamsim.run(config("thesis", "gate.yaml"), trajectory=True)
    ax = beamsim.plot.trajectory(r)
    tr = r["trajectory"]
    path, touch = ax.get_lines()
    flagged = (tr["contact1"] != 0) | (tr["contact2"] != 0)
    assert flagged.any() and np.array_equal(touch.get_xdata(), tr["x"][flagged])
    assert np.array_equal(path.get_ydata(), tr["y"])
    with pytest.raises(ValueError, match="no trajectory"):
        beamsim.plot.trajectory(beamsim.run(config("thesis", "gate.yaml")))
