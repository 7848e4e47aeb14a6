"""Figures of beamsim's results with matplotlib (Debian: python3-matplotlib),
for a Python user who wants them in a notebook or a script rather than from
`beamsim plot`:

    import beamsim, beamsim.plot
    s = beamsim.sweep("configs/thesis/h1_symmetric.yaml", trials=100, trajectories=2)
    beamsim.plot.p_traverse(s)               # p_traverse against the first grid axis
    beamsim.plot.trajectories(s)             # the kept trials' paths
    beamsim.plot.trajectory(beamsim.run("configs/thesis/gate.yaml", trajectory=True))

Each function draws into ax (a matplotlib Axes; None: a new figure's) and
returns it; the numbers drawn are the result's own, nothing recomputed but
the arrangement."""

import numpy as np

__all__ = ["p_traverse", "trajectories", "trajectory"]


def _axes(ax):
    try:
        import matplotlib.pyplot as plt
    except ImportError as e:
        raise ImportError("beamsim.plot needs matplotlib (Debian: python3-matplotlib, which "
                          "scripts/deps.sh installs; or pip install matplotlib)") from e
    if ax is None:
        _, ax = plt.subplots()
    return ax


def p_traverse(result, x=None, ax=None):
    """p_traverse of each group of a sweep (beamsim.sweep's result) against
    the grid axis x (a key of the groups' params; None: the first), one line
    per value of the other axes, with Wilson's 95% interval as error bars
    (summary.json's ci95). A group without random force (one trial) is
    drawn as a point without bars."""
    ax = _axes(ax)
    groups = result["groups"]
    keys = list(groups[0]["params"]) if groups and groups[0]["params"] else []
    if not keys:
        raise ValueError("p_traverse: the sweep has no grid axis to draw against")
    x = keys[0] if x is None else x
    if x not in keys:
        raise ValueError(f"p_traverse: x {x!r}: expected one of the grid's keys {keys}")
    others = [k for k in keys if k != x]
    lines = {}
    for g in groups:
        label = ", ".join(f"{k} = {g['params'][k]}" for k in others)
        lines.setdefault(label, []).append(g)
    for label, gs in lines.items():
        xs = np.array([g["params"][x] for g in gs], dtype=float)
        p = np.array([g["p_traverse"] for g in gs], dtype=float)
        lo = np.array([g["ci95"][0] for g in gs], dtype=float)
        hi = np.array([g["ci95"][1] for g in gs], dtype=float)
        ax.errorbar(xs, p, yerr=[p - lo, hi - p], marker="o", capsize=3, label=label or None)
    ax.set_xlabel(x)
    ax.set_ylabel("p_traverse (Wilson 95%)")
    ax.set_ylim(-0.02, 1.02)
    if any(lines):
        ax.legend(fontsize="small")
    return ax


def trajectories(result, ax=None, groups=None):
    """The kept trials' paths of a sweep (beamsim.sweep(..., trajectories=N)):
    y against x, one line per (group, trial), of the groups given (None:
    all)."""
    ax = _axes(ax)
    kept = result.get("trajectories") or {}
    if not kept:
        raise ValueError("trajectories: the sweep kept none (sweep(..., trajectories=N))")
    for (g, t), cols in sorted(kept.items()):
        if groups is None or g in groups:
            ax.plot(cols["x"], cols["y"], lw=0.8, label=f"group {g}, trial {t}")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    return ax


def trajectory(run_result, ax=None):
    """One trial's path (beamsim.run(..., trajectory=True)): y against x,
    the steps in contact with a beam drawn as points over it."""
    ax = _axes(ax)
    tr = run_result.get("trajectory")
    if tr is None:
        raise ValueError("trajectory: the run has no trajectory (run(..., trajectory=True))")
    ax.plot(tr["x"], tr["y"], lw=1.0, label="path")
    touch = np.zeros(len(tr["x"]), dtype=bool)
    for name, col in tr.items():
        if name.startswith("contact") and name[7:].isdigit():
            touch |= col != 0
    ax.plot(tr["x"][touch], tr["y"][touch], ".", ms=3, label="in contact")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize="small")
    return ax
