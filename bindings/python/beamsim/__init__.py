"""beamsim: the beam-gate traversal simulator (libbeamsim) from Python.

    import beamsim
    r = beamsim.run("configs/thesis/h1_symmetric.yaml", group=3, trial=2, trajectory=True)
    r["outcome"], r["t_end"], r["trajectory"]["y"]        # a NumPy array
    s = beamsim.sweep("configs/thesis/h1_symmetric.yaml", trials=50)
    [g["p_traverse"] for g in s["groups"]], s["trials"]["outcome"]

Each call is the command line's: run is `beamsim run`, sweep is `beamsim
sweep`, compare is `beamsim compare`, landscape is `beamsim landscape`, with
the same numbers, and bad input raises ValueError with the one-line message
`beamsim` prints. Groups and trials count from 0, as in trials.csv. Long
calls release the GIL; Ctrl-C stops a sweep or a comparison
(KeyboardInterrupt). See docs/bindings.md.
"""

import json
import math
import numbers
import os
import sys
import tempfile
import warnings

from ._built import python as _BUILT_PYTHON, version as _BUILT_VERSION

try:
    import numpy as np
except ImportError as _e:
    raise ImportError(
        f"beamsim needs NumPy, which this Python ({sys.executable}) does not have: run "
        f"{_BUILT_PYTHON}, the Python beamsim was built for (Debian's python3 with "
        f"python3-numpy, which scripts/deps.sh installs), or install NumPy into this one"
    ) from _e

try:
    from . import _beamsim
except ImportError as _e:
    _here = "%d.%d" % sys.version_info[:2]
    raise ImportError(
        f"beamsim's extension was built for Python {_BUILT_VERSION} ({_BUILT_PYTHON}) and "
        f"the NumPy it has; this is Python {_here} ({sys.executable}): run {_BUILT_PYTHON}, "
        f"or build beamsim for this one (cmake -DPython3_EXECUTABLE={sys.executable}, or "
        f"pip install --no-build-isolation . into it): {_e}"
    ) from _e

__all__ = ["run", "sweep", "compare", "landscape", "load", "version", "backends", "World"]


def version():
    """libbeamsim's version."""
    return _beamsim.version()


def backends():
    """The backends compiled in, by name, as `beamsim backends` lists them;
    the first is the default."""
    return list(_beamsim.backends())


backends_list = backends  # for functions whose argument is named backends


# ---- arguments as the command line gives them ------------------------------


def _text(v):
    """A value as the YAML text --set takes (7 -> "7", [0, 5] -> "[0, 5]")."""
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Real):
        x = float(v)
        if not math.isfinite(x):
            raise ValueError(f"{x!r}: expected a finite number")
        return repr(x)
    if isinstance(v, str):
        return v
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_text(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k}: {_text(x)}" for k, x in v.items()) + "}"
    raise TypeError(f"{v!r}: expected a number, str, list or dict")


def _sets(sets):
    """--set KEY=VALUE overrides: a dict {key: value}, or "KEY=VALUE" strings."""
    if sets is None:
        return []
    items = sets.items() if isinstance(sets, dict) else sets
    if isinstance(items, str):
        items = [items]
    out = []
    for item in items:
        if isinstance(item, str):
            key, eq, value = item.partition("=")
            if not eq or not key:
                raise ValueError(f"--set {item}: expected KEY=VALUE, e.g. "
                                 "--set effects.propulsion.force=7")
        elif isinstance(item, (tuple, list)) and len(item) == 2:
            key, value = item
            value = _text(value)
        else:
            raise TypeError(f"set: expected a dict {{key: value}}, \"KEY=VALUE\" strings or "
                            f"(key, value) pairs, got {item!r}")
        out.append((key, value, f"--set {key}={value}"))
    return out


def _grid(grid):
    """--grid axes: a dict {key: [values]}."""
    if grid is None:
        return []
    if not isinstance(grid, dict):
        raise TypeError("grid: expected a dict {key: [values]}")
    out = []
    for key, values in grid.items():
        if isinstance(values, (str, numbers.Number)):
            values = [values]
        # one origin for the axis: the library names a value "--grid KEY=VALUE"
        out.append((key, [_text(v) for v in values], f"--grid {key}"))
    return out


def _opts(opts):
    """--backend-opt KEY=VALUE options: a dict, or "KEY=VALUE" strings."""
    if opts is None:
        return []
    if isinstance(opts, dict):
        return [f"{k}={_text(v)}" for k, v in opts.items()]
    if isinstance(opts, str):
        return [opts]
    return list(opts)


def _no_nul(what, text):
    """A path or name the library takes as a C string, which ends at a NUL:
    one in it is refused naming the argument (ValueError); None passes."""
    if text is not None:
        text = os.fspath(text)
        if isinstance(text, str):
            _beamsim.bsim_text_check(what, text)


_INT32_MAX = 2**31 - 1


def _count(name, value, least, most=_INT32_MAX):
    """An integer option as the command line checks it (0 for None: the
    library's default)."""
    if value is None:
        return 0
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or \
            not least <= value <= most:
        raise ValueError(f"--{name} {value}: expected an integer >= {least}")
    return int(value)


def _backend(backend, what="backend"):
    """A backend argument: None (the default), a name or compare side
    "NAME[:KEY=VALUE]..." (str), or a class written in Python (a backend in
    Python: registered once, then named by its `name`)."""
    if backend is None:
        return None
    if isinstance(backend, type):
        for method in ("advance", "state"):
            if not callable(getattr(backend, method, None)):
                raise TypeError(f"{what} {backend.__name__}: a backend in Python needs the "
                                f"methods advance(force, torque, h) and state() "
                                f"(docs/bindings.md, \"A backend in Python\")")
        name = getattr(backend, "name", backend.__name__)
        if not isinstance(name, str):
            raise TypeError(f"{what} {backend.__name__}: its name must be a str")
        doc = (backend.__doc__ or "").strip().splitlines()
        about = doc[0] if doc else f"a backend in Python, {backend.__module__}.{backend.__qualname__}"
        _no_nul(what, name)
        return _beamsim.register_backend(backend, name, about)
    _no_nul(what, backend)
    return backend


def _seed(seed):
    if seed is None:
        return None
    return _count("seed", seed, 0, 2**64 - 1)


# ---- files of an output directory ------------------------------------------


def read_csv(path):
    """One CSV file of beamsim as a dict of NumPy arrays by column: int64 if
    every field of the column is an integer, float64 if every field is a
    number (an empty field is NaN, not measured), else str. The arrays are
    made while the rows are read, so what is held is the arrays themselves
    (trials.csv: about 330 bytes a row, docs/bindings.md), not the file."""
    return _beamsim.read_table(os.fspath(path))


def load(path):
    """Reads an output directory of beamsim (sweep, compare, run --out,
    landscape, ...) into a dict: each CSV file a dict of NumPy arrays by
    column (trials.csv: load(d)["trials"]["x_end"]), each JSON file what
    json gives, each folder (a comparison's side) a dict of the same kind,
    by name without the extension (a JSON file beside a CSV file of the
    same name by its whole name: "landscape" and "landscape.json"). A
    single file is read alone."""
    path = os.fspath(path)
    if os.path.isfile(path):
        if path.endswith(".csv"):
            return read_csv(path)
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    if not os.path.isdir(path):
        raise ValueError(f"{path}: expected an output directory of beamsim or a CSV or JSON "
                         "file, got nothing there")
    out = {}
    names = sorted(os.listdir(path))
    for name in names:
        full = os.path.join(path, name)
        stem, ext = os.path.splitext(name)
        if name.startswith(".") or name == "inputs":
            continue
        if os.path.isdir(full):
            sub = load(full)
            if sub:
                out[name] = sub
        elif ext == ".csv":
            out[stem] = read_csv(full)
        elif ext == ".json":
            # landscape.json beside landscape.csv: the CSV keeps the name.
            with open(full, encoding="utf-8") as f:
                out[name if stem + ".csv" in names else stem] = json.load(f)
    return out


# ---- the calls -------------------------------------------------------------


def run(scene, seed=None, group=0, trial=0, backend=None, set=None, backend_opt=None,
        trajectory=False, stride=1, grid=None):
    """One trial, as `beamsim run SCENE --json` runs it.

    scene: a scene file; an experiment file (trial `trial` of group `group`
    as `beamsim sweep` runs it, the group's grid values applied); or the
    output directory of a sweep or comparison (the trial as that run ran it,
    with its seed, backend and options; backend names a comparison's side).
    seed: None is the experiment's (a scene's: 1). backend: a name of
    backends() (None: the first, the default), or "NAME:KEY=VALUE..." as a
    compare side.
    set: {dotted key: value} scene overrides; backend_opt: {knob: value};
    grid: an experiment's axes {key: [values]}, as sweep's.

    Returns run --json's object as a dict (the result's fields by their
    names, as the library lists them: docs/files.md, "run"), with "row"
    (the trial's trials.csv fields), "grid" (an experiment's group values) and, for a
    stored run, "stored_row" (its row in trials.csv). trajectory=True adds
    "trajectory": a dict of NumPy arrays by trajectory.csv column (t, x, y,
    vx, vy, theta1, omega1, ..., f_rand, contact1, ..., e_kin, e_beam,
    e_prop), a row every `stride` steps, and "ledger_rows", the energy
    ledger at the same times by ledger.csv column (t, e_kin, e_beam, e_mech,
    w_prop, w_rand, damper, impact, contact, correction, residual, sleep,
    reset: J, each flow summed from t = 0). An unstable trial (outcome
    "unstable") and a replay that differs from its stored row are warned
    of (RuntimeWarning)."""
    _no_nul("scene", scene)
    backend = _backend(backend)
    r = _beamsim.run(os.fspath(scene), _seed(seed), _count("group", group, 0),
                     _count("trial", trial, 0), backend, _sets(set), _opts(backend_opt),
                     bool(trajectory), _count("stride", stride, 1), _grid(grid))
    d = json.loads(r["json"])
    d["row"] = r["row"]
    if r["kind"] != "scene":
        d["grid"] = r["grid"]
    if "stored_row" in r:
        d["stored_row"] = r["stored_row"]
        if r["stored_row"] != r["row"]:
            warnings.warn(f"the replay of group {d['group']}, trial {d['trial']} differs from "
                          f"its row in trials.csv: {r['row']}, stored {r['stored_row']}",
                          RuntimeWarning, stacklevel=2)
    if d["outcome"] == "unstable":
        warnings.warn(f"{d['backend']} backend: unstable trial: {r['instability_text']}",
                      RuntimeWarning, stacklevel=2)
    if trajectory:
        d["trajectory"] = r["trajectory"]
        d["ledger_rows"] = r["ledger_rows"]
    return d


# The bytes a cell of trials.csv takes in read_csv's arrays, at most: 8 a
# number; a text column (outcome, type, location, path) 4 a character of its
# longest string, which for a gate's trials stays under this on average
# (docs/bindings.md "Memory").
_CELL_BYTES = 16.0


class _Dir:
    """out, or a temporary directory removed afterwards."""

    def __init__(self, out, name):
        self.out, self.name, self.tmp = out, name, None

    def __enter__(self):
        if self.out is not None:
            return os.fspath(self.out)
        self.tmp = tempfile.TemporaryDirectory(prefix="beamsim-")
        return os.path.join(self.tmp.name, self.name)

    def __exit__(self, *exc):
        if self.tmp is not None:
            self.tmp.cleanup()


def sweep(experiment, trials=None, threads=None, backend=None, set=None, grid=None, seed=None,
          backend_opt=None, out=None, progress=None, trajectories=0, resume=False,
          overwrite=False):
    """Every trial of every group of an experiment, as `beamsim sweep
    EXPERIMENT --out DIR` runs them (the same numbers, whatever threads).

    trials, seed: instead of the file's; threads: None is all cores;
    backend, set, backend_opt as in run; grid: {key: [values]} axes that
    replace or join the file's. out: keep the output directory there (a
    replayable run: beamsim.run(out, group=g, trial=t)); None: a temporary
    one. progress: callable(done, total), called with the GIL after each
    finished trial. trajectories: the first trials of each group whose
    trajectories are kept (trajectories.csv, as --trajectories). resume:
    continue the stopped sweep in out. overwrite: replace the finished
    result (or a stopped sweep's journal) in out; without it such an out is
    refused (ValueError), as it is by `beamsim sweep` without --overwrite.

    Returns a dict: "groups" (summary.json's groups: params, trials,
    traversed, side_exit, stuck, left, right, p_traverse, ci95, ...),
    "trials" (trials.csv as a dict of NumPy arrays by column, read_csv),
    "summary" (all of summary.json), "trajectories" (the kept trials'
    trajectories, {(group, trial): {column: array}}: t, x, y, theta1,
    theta2, contact1, contact2, each (n_rows,); {} with trajectories=0),
    "threads" and "out". A sweep whose
    arrays would not fit in the memory available is refused before it
    runs (ValueError). Unstable trials are warned of (RuntimeWarning);
    Ctrl-C stops the sweep (KeyboardInterrupt)."""
    _no_nul("experiment", experiment)
    _no_nul("out", out)
    backend = _backend(backend)
    with _Dir(out, "sweep") as d:
        info = _beamsim.sweep(os.fspath(experiment), d, _count("trials", trials, 1),
                              _count("threads", threads, 1, 4096), _seed(seed), backend,
                              _sets(set), _grid(grid), _opts(backend_opt), progress,
                              _count("trajectories", trajectories, 0), bool(resume),
                              bool(overwrite), _CELL_BYTES)
        files = load(d)
    if info["unstable"]:
        text = info["unstable_text"]
        if out is None:
            text = text.replace(f"{d}/trials.csv", "the trials' outcome")
        warnings.warn(text, RuntimeWarning, stacklevel=2)
    summary = files["summary"]
    return {"groups": summary["groups"], "trials": files["trials"], "summary": summary,
            "trajectories": _by_trial(files.get("trajectories")), "threads": info["threads"],
            "out": out}


def _by_trial(table):
    """trajectories.csv's rows split by trial: {(group, trial): {column: array}}, each
    array a kept trial's (n_rows,), in the file's order; {} without the file."""
    if not table:
        return {}
    g, t = table["group"], table["trial"]
    # rows of one trial are consecutive: cut where (group, trial) changes
    cuts = np.flatnonzero((np.diff(g) != 0) | (np.diff(t) != 0)) + 1
    out = {}
    for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, len(g)]):
        out[(int(g[lo]), int(t[lo]))] = {k: v[lo:hi] for k, v in table.items()
                                          if k not in ("group", "trial")}
    return out


def compare(experiment, backends=None, trials=None, threads=None, set=None,
            grid=None, seed=None, out=None, progress=None, resume=False, overwrite=False):
    """The experiment on two or more sides (at most 8) with the same
    random-force schedules, as `beamsim compare EXPERIMENT --backends A,B,...
    --out DIR` runs it. A side is "NAME[:KEY=VALUE]...". resume: continue
    the stopped comparison in out, as sweep's. backends None: the first two
    of backends(), as compare's default. overwrite: replace the
    finished result (or a stopped comparison's journal) in out; without it
    such an out is refused.
    Returns a dict: "report" (report.json: with three sides or more, its
    "sides", "pairwise" and "odd_one_out" too), "pairs" (pairs.csv as
    arrays), "sides" (each side's summary.json and trials arrays, by label,
    in the order given), "n_disagree" (groups in which some pair of sides
    disagrees) and "out"."""
    if backends is None:
        backends = tuple(backends_list())[:2]
    if isinstance(backends, (str, bytes)):
        raise TypeError("backends: expected a sequence of sides NAME[:KEY=VALUE]..., e.g. "
                        f"{tuple(backends_list()[:2])}")
    labels = tuple(_backend(b, "backends") for b in backends)
    if not 2 <= len(labels) <= 8:
        raise ValueError(f"backends: {len(labels)} sides; expected 2 to 8")
    _no_nul("experiment", experiment)
    _no_nul("out", out)
    with _Dir(out, "compare") as d:
        info = _beamsim.compare(os.fspath(experiment), d, labels, _count("trials", trials, 1),
                                _count("threads", threads, 1, 4096), _seed(seed), _sets(set),
                                _grid(grid), progress, bool(resume), bool(overwrite))
        files = load(d)
    sides = {}
    for label, name in zip(labels, info["dirs"]):
        side = files.get(name, {})
        sides[label] = {"groups": side.get("summary", {}).get("groups"),
                        "trials": side.get("trials"), "summary": side.get("summary")}
    for label, n in zip(labels, info["unstable"]):
        if n:
            warnings.warn(f"{label}: {n} unstable trials", RuntimeWarning, stacklevel=2)
    return {"report": files.get("report"), "pairs": files.get("pairs"), "sides": sides,
            "n_disagree": info["n_disagree"], "out": out}


def landscape(scene, set=None, resolution=None, region=None):
    """The potential energy landscape of a scene and its passes, as `beamsim
    landscape SCENE` computes them. resolution: the grid spacing in m (None:
    the region's longer side / 260); region: (x0, x1, y0, y1) in m (None:
    the trial's arena).

    Returns a dict: "x" (nx), "y" (ny), "e_total", "e_beam", "e_prop"
    ((ny, nx) arrays, J, row j at y[j]: landscape.csv's rows), "theta"
    ((beams, ny, nx), rad), and what landscape.json holds: "grid", "start",
    "far_y", "lowest_pass" (over any beam) and "barriers" (the lowest pass
    over each beam: [{"beam": 1, "pass": {...}}, ...]), a pass being kind,
    crossed (the beam, from 1), x, y, e_total, e_beam, e_prop, height,
    above_start, floor, grid, refine_spacing, refine_change and path (an
    (n, 2) array)."""
    if resolution is not None and not (resolution > 0 and math.isfinite(resolution)):
        raise ValueError(f"--resolution {resolution}: expected a grid spacing > 0 in m")
    if region is not None:
        region = tuple(float(v) for v in region)
        if len(region) != 4 or not (region[0] < region[1] and region[2] < region[3]):
            raise ValueError(f"--region {region}: expected X0,X1,Y0,Y1 in m with X0 < X1 "
                             "and Y0 < Y1, e.g. --region -25,25,0,65")
    _no_nul("scene", scene)
    return _beamsim.landscape(os.fspath(scene), _sets(set),
                              float(resolution) if resolution is not None else 0.0, region)


def _entries(entries):
    """--entries: None, one str or path, or a sequence of them ("self",
    "self:N", "flow", "flow:N", or gate_entries.csv paths)."""
    if entries is None:
        return None
    if isinstance(entries, (str, os.PathLike)):
        entries = [entries]
    out = []
    for e in entries:
        _no_nul("entries", e)
        out.append(os.fspath(e))
    return out


def markov_build(experiment, out, trials=None, bins=None, vmax=None, entries=None, seed=None,
                 threads=None, backend=None, backend_opt=None, set=None, grid=None,
                 progress=None, start_trials=None, after_start=None, train=None,
                 crossings=None, per_crossing=None, after_trials=None, method=None, k=None):
    """What the chain predicts the lattices of an experiment from, built into
    the directory out as `beamsim markov build EXPERIMENT --out DIR` builds
    it (docs/markov.md): the same files, byte for byte, for the same
    arguments.

    method: "nearest" (None, unless an argument only maps have is given):
    the training fields of the nearest-neighbour walks, one per gate kind
    of the lattices' physics (train trials each, None: 10,000; k: each
    step drawn from the k nearest visits, None: 20), which markov_predict
    and markov_validate with map=out walk over; "maps" (None with any of
    trials, bins, vmax, entries, start_trials, after_start, crossings,
    per_crossing, after_trials): the single-gate maps, one per pair of beam
    stiffnesses, as below.

    out is a cache: maps already there with the same key are reused, the
    others built there. trials: single gates per entry bin (None: 50);
    start_trials: of the start bin (None: 16,000, or trials with self or flow
    entries); after_start: True (None: the default, False with self or flow
    entries) continues each start trial that leaves into a gate there from
    its exact state, for every pair of stiffnesses, and the chain takes the
    first two gates from those; False: entry bins from the start on;
    after_trials: the first start trials continued there (None: 8,000; the
    others take the continuations of those that entered the same gate), 0:
    every start trial; train: trials of the maps' training field, a 21 x 21 field of the
    lattice's gate kinds at random whose gate entries the bins' states are drawn from
    (None: 4,000; run only when a map is built), 0: states uniform in each
    bin; crossings: True (None, with a training field) counts each bin
    from the training field's own crossings of the map's gate kind entered
    in it, topped up with single gates as per_crossing says; False: trials
    single gates a bin; per_crossing: single gates a bin is topped up to
    for each crossing that entered it (as for one where none did), at most
    trials (None: 5), 0: every bin topped up to trials; bins: (positions,
    speeds, directions), 1 to 64 each (None: (14, 6, 13));
    vmax: m/s, the top of the speed bins (None: 40); entries: gate_entries.csv
    paths (a bin's states drawn from them), or "self", "self:N", "flow",
    "flow:N" as --entries; seed: of the states and schedules (None: 1);
    backend, backend_opt, set, grid, threads as in sweep. progress:
    callable(done, total) over the single gates (the walks': the training
    trials); Ctrl-C stops the build (the maps or fields finished are kept:
    the same call builds the rest).

    Returns a dict: "method" ("nearest" or "maps"), "maps" (one per group's
    map, or the walks' training field, in order: {"group", "k" (left,
    right, N m/rad), "key" (its files' name, map_HASH or visits_HASH),
    "how" ("built" or "reused"), "pass"}), "built", "reused", "groups",
    "cpu_seconds" (of those built now), "bins" (entry bins a map, the
    start's included; 0 for the walks), "trials" (a bin's, or the walks'
    training trials), "visits" (the walks' training fields' visits), "run",
    "out" and "scope" (where maps of this method were measured to fall
    short on layouts they were not built on; "" for the walks)."""
    if method is not None and method not in ("nearest", "maps"):
        raise ValueError(f"method {method!r}: expected 'nearest' or 'maps'")
    if vmax is not None and not (vmax > 0 and math.isfinite(vmax)):
        raise ValueError(f"--vmax {vmax}: expected a speed > 0 in m/s")
    if bins is not None:
        bins = tuple(bins)
        if len(bins) != 3 or any(isinstance(b, bool) or not isinstance(b, numbers.Integral)
                                 or not 1 <= b <= 64 for b in bins):
            raise ValueError(f"--bins {bins}: expected P,S,D: 1 to 64 bins of position, "
                             "speed and direction, e.g. (4, 4, 3)")
        bins = tuple(int(b) for b in bins)
    _no_nul("experiment", experiment)
    _no_nul("out", out)
    backend = _backend(backend)
    info = _beamsim.markov_build(os.fspath(experiment), os.fspath(out),
                                 _count("trials", trials, 1), bins,
                                 float(vmax) if vmax is not None else 0.0, _entries(entries),
                                 _seed(seed), _count("threads", threads, 1, 4096), backend,
                                 _sets(set), _grid(grid), _opts(backend_opt), progress,
                                 _count("start_trials", start_trials, 1, 1000000),
                                 -1 if after_start is None else int(bool(after_start)),
                                 -1 if train is None else _count("train", train, 0, 1000000),
                                 -1 if crossings is None else int(bool(crossings)),
                                 -1 if per_crossing is None
                                 else _count("per_crossing", per_crossing, 0, 1000000),
                                 -1 if after_trials is None
                                 else _count("after_trials", after_trials, 0, 1000000),
                                 method, _count("k", k, 1, 64))
    info["out"] = out
    return info


def _method(map, visits, k, train):
    """The one of map and visits given, and whether the prediction walks
    (visits, or a build of the walks in map); k and train with visits
    only."""
    if (map is None) == (visits is None):
        raise ValueError("expected one of map (a directory of beamsim markov build) and "
                         "visits (nearest-neighbour walks)")
    _no_nul("map", map)
    _no_nul("visits", visits)
    if map is not None and (k is not None or train is not None):
        raise ValueError(f"{'k' if k is not None else 'train'}: for visits only (the build "
                         "in map holds its own)")
    map = os.fspath(map) if map is not None else None
    walks = visits is not None or _beamsim.markov_method(map) == "nearest"
    return map, os.fspath(visits) if visits is not None else None, walks


def markov_predict(scene, map=None, set=None, tol=None, gates=None, walks=None, out=None,
                   overwrite=False, visits=None, k=None, train=None, seed=None, threads=None):
    """A gate lattice predicted from the build in the directory map, as
    `beamsim markov predict SCENE --map DIR --json` predicts it: the same
    numbers for the same build. A build of the walks (markov_build's
    default) is walked over: walks (None: 200000), threads (None: all
    cores; the same numbers on any); the build's k, training trials and
    seed its own. A build of maps is solved as below. Or, with visits instead of map, by
    nearest-neighbour walks over the visits of training fields kept in the
    directory visits (those missing run there first), as `beamsim markov
    predict SCENE --visits DIR --json`: walks (None: 200000) of them, each
    step from the k nearest visits (None: 20), training fields of train
    trials a gate kind (None: 10000), seed (None: 1), threads (None: all
    cores; the same numbers on any); tol and gates are for map.

    scene: a lattice scene file; set: {dotted key: value} overrides; tol:
    the probability left in the field at which the solution stops, in (0,
    1) (None: the maps' sampling tolerance, 1 / (32 sqrt(trials per bin)));
    gates: True for the distribution of gates visited (the series), False
    for none (None: with out only); walks: walks of the semi-Markov chain
    for the time to the outcome (None: 100000; 0: none). out: also write
    prediction.csv, prediction_gates.csv, time.csv, their .mat twins and
    the figures there; overwrite: replace the result out holds (without it
    such an out is refused, ValueError).

    Returns --json's object as a dict ("totals" {end, side, stuck},
    "locations" [{location, kind, p}], "p_gates", "mean_gates",
    "mean_time", "at_duration", "solve", "states", "tol", ...) with "p_time"
    (a (bins, 3) array: the probability that the outcome, end, side or
    stuck, happens in each time bin), "time_bin" (s) and "p_loc_time" (each
    location's p at the trial's duration), both empty without walks."""
    if tol is not None and not (0.0 < tol < 1.0):
        raise ValueError(f"--tol {tol}: expected the probability left in the field at which "
                         "the solution stops, in (0, 1), e.g. 1e-12")
    _no_nul("scene", scene)
    _no_nul("out", out)
    map, visits, walking = _method(map, visits, k, train)
    if walking and (tol is not None or gates is not None):
        raise ValueError("tol, gates: for maps only")
    if map is not None and seed is not None:
        raise ValueError("seed: for visits only (map holds its own)")
    if not walking and threads is not None:
        raise ValueError("threads: for the walks only (the maps of map hold their own)")
    if walking:
        walks = 200000 if walks is None else _count("walks", walks, 1, 100000000)
    else:
        walks = 100000 if walks is None else _count("walks", walks, 0, 100000000)
    r = _beamsim.markov_predict(os.fspath(scene), map, _sets(set),
                                float(tol) if tol is not None else 0.0,
                                -1 if gates is None else int(bool(gates)), walks,
                                os.fspath(out) if out is not None else None, bool(overwrite),
                                visits, _count("k", k, 1, 64), _count("train", train, 1),
                                _seed(seed), _count("threads", threads, 1, 4096))
    d = json.loads(r["json"])
    d["p_time"], d["time_bin"], d["p_loc_time"] = r["p_time"], r["time_bin"], r["p_loc_time"]
    return d


def markov_validate(experiment, map=None, out=None, trials=None, seed=None, threads=None,
                    set=None, grid=None, bootstrap=None, progress=None, resume=False,
                    overwrite=False, visits=None, k=None, train=None, walks=None):
    """Every group of a lattice experiment simulated directly, under the
    essay's protocol and as a whole world, against the chain of the maps in
    map, as `beamsim markov validate EXPERIMENT --map DIR --out OUT` does
    it. trials, seed: instead of the experiment's; bootstrap: resamples of
    the simulation (None: 2000); out: keep the output directory there (None:
    a temporary one); progress, resume, overwrite as in sweep.

    Returns validate.json as a dict ("checks": one per group and protocol,
    essay then world: group, protocol, trials, tv, tv_sampling,
    tv_sampling95, tv_map, gates_sim, gates_chain, sim_cpu_seconds,
    predict_cpu_seconds, speedup, break_even_lattices, states, exact and,
    with the maps' holding times, "time"; "map_cpu_seconds", "entry_bins",
    "trials_per_bin", "maps_scope", ...) with "files" (the directory's files as load
    reads them: "validate" (validate.csv), "gates", "time_validate", ...)
    and "out". With map a build of the walks (markov_build's default), the
    prediction by its nearest-neighbour walks (walks: None, 200000). With
    visits instead of map: the prediction by
    nearest-neighbour walks, as markov_predict's (k, train, walks), as
    `beamsim markov validate EXPERIMENT --visits DIR` makes it."""
    _no_nul("experiment", experiment)
    _no_nul("out", out)
    map, visits, walking = _method(map, visits, k, train)
    if not walking and walks is not None:
        raise ValueError("walks: for the walks only (the maps of map hold their own)")
    with _Dir(out, "validate") as d:
        _beamsim.markov_validate(os.fspath(experiment), map, d,
                                 _count("trials", trials, 1), _seed(seed),
                                 _count("threads", threads, 1, 4096), _sets(set), _grid(grid),
                                 -1 if bootstrap is None else
                                 _count("bootstrap", bootstrap, 0, 1000000),
                                 progress, bool(resume), bool(overwrite), visits,
                                 _count("k", k, 1, 64), _count("train", train, 1),
                                 _count("walks", walks, 1, 100000000))
        files = load(d)
    info = files.pop("validate.json")
    info["files"] = files
    info["out"] = out
    return info


class World:
    """A world stepped by hand, on any backend: the scene's bodies and beams
    in a backend's world, advanced by the caller a step at a time
    (libbeamsim's stepper, beamsim/stepper.h).

    scene, seed, group, trial, backend, set, backend_opt and grid name the
    trial as run() names it: a scene file, an experiment file (trial `trial`
    of group `group`, the group's grid values applied) or the output
    directory of a sweep or comparison (its seed, backend and options;
    backend names a comparison's side). The world starts as that trial
    starts.

    step(force=None, n=1, torque=0.0): n steps of the scene's dt. With force
    None, under the scene's own effects (propulsion, the random force of the
    trial's schedule, drag, ...), each step's force from the state it starts
    at: n steps are the trial's first n steps as run() and sweep() make
    them, to the bit. With force (F_x, F_y) in N (and torque in N m), that
    force held over the n steps instead. A step that fails (the backend's
    error, a state no longer finite) raises RuntimeError naming it.

    state: the state after the last step, a dict: step, t (s), x, v (body
    centre and velocity, arrays of 2), heading, angular_velocity, theta,
    omega (arrays by beam), contact (int32: 0 none, 1 tangent, 2 tip, the
    contact flag every backend reports), touched (int32) and impulse (N s,
    what each beam exchanged with the body in the last step), force (the
    last step's F_x, F_y, torque), e_kin and e_elastic (J), energy (the last
    step's flows: damper, impact, contact, correction, sleep), impacts and
    solver (the backend's counts).

    reset(): back to step 0. dt: the time step (s); backend: its name."""

    def __init__(self, scene, backend=None, seed=None, group=0, trial=0, set=None,
                 backend_opt=None, grid=None):
        _no_nul("scene", scene)
        backend = _backend(backend)
        self._w = _beamsim.World(os.fspath(scene), _seed(seed), _count("group", group, 0),
                                 _count("trial", trial, 0), backend, _sets(set),
                                 _opts(backend_opt), _grid(grid))

    def step(self, force=None, n=1, torque=0.0):
        """n steps: under the scene's own forces (force None), or under
        force (F_x, F_y), N, and torque, N m, held over them."""
        if isinstance(n, bool) or not isinstance(n, numbers.Integral) or n < 1:
            raise ValueError(f"n {n!r}: expected an integer >= 1")
        if force is not None:
            force = tuple(float(f) for f in force)
            if len(force) != 2:
                raise ValueError(f"force {force!r}: expected (F_x, F_y) in N")
        self._w.step(force, int(n), float(torque))

    def reset(self):
        """Back to step 0: the trial's start."""
        self._w.reset()

    @property
    def state(self):
        """The state after the last step (a dict, the class's doc)."""
        return self._w.state

    @property
    def dt(self):
        """The scene's time step, s."""
        return self._w.dt

    @property
    def backend(self):
        """The backend's name (a stored comparison's side label)."""
        return self._w.backend

    def __repr__(self):
        return f"beamsim.World(backend={self.backend!r}, step={self.state['step']})"
