"""The column arrays of a sweep and of read_csv against the CSV read here
with Python's csv module, each column typed by the rule read_csv states
(int64 if every field is an integer, float64 if every field is a number or
empty, else str); their memory against the arrays' own size; a sweep whose
arrays would not fit in memory refused before it runs."""

import csv
import math
import os
import subprocess
import sys

import numpy as np
import pytest

import beamsim
from conftest import cli


def typed(fields):
    """A column's fields as the rule types them: the independent truth."""
    try:
        return np.array([int(v) for v in fields], dtype=np.int64)
    except ValueError:
        pass
    try:
        return np.array([float(v) if v != "" else math.nan for v in fields],
                        dtype=np.float64)
    except ValueError:
        return np.array(fields, dtype=str)


def reference(path):
    with open(path, newline="", encoding="utf-8") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    return {name: typed([row[c] for row in body]) for c, name in enumerate(header)}


def same(arrays, want):
    assert list(arrays) == list(want)
    for name, w in want.items():
        a = arrays[name]
        assert a.dtype == w.dtype, (name, a.dtype, w.dtype)
        assert a.shape == w.shape, name
        if a.dtype.kind == "f":
            assert np.array_equal(a, w, equal_nan=True), name
        else:
            assert np.array_equal(a, w), name


def test_sweep_columns_are_trials_csv(gate, tmp_path):
    """Every column of a sweep's trials (the grid's too: numbers, and text
    that trials.csv quotes) is trials.csv's, field for field, and so is a
    stored sweep's, read by load."""
    exp = tmp_path / "text_axis.yaml"
    exp.write_text(f"scene: {gate}\ntrials: 5\nseed: 2\nset:\n  integration.max_steps: 40\n"
                   "grid:\n  name: [\"a, b\", 'say \"c\"']\n  effects.propulsion.force: [7]\n")
    s = beamsim.sweep(exp, grid={"beams.0.stiffness": [150, 400.5]}, out=tmp_path / "s")
    want = reference(tmp_path / "s" / "trials.csv")
    same(s["trials"], want)
    assert len(s["trials"]["group"]) == 4 * 5
    assert s["trials"]["outcome"].dtype.kind == "U"
    assert s["trials"]["group"].dtype == np.int64
    assert s["trials"]["beams.0.stiffness"].dtype == np.float64
    assert set(s["trials"]["name"]) == {'"a, b"', "'say \"c\"'"}
    same(beamsim.load(tmp_path / "s")["trials"], want)


def test_read_csv_types_as_python(tmp_path):
    """Columns that change type part-way (an integer column meeting a
    fraction or an empty field, numbers meeting text late: read again),
    empty fields, quoted commas, quotes and line breaks, other scripts,
    and a table of no rows."""
    rows = [["i", "frac", "gap", "late", "word", "blank", "quoted", "emptytext"]]
    for k in range(3000):
        rows.append([str(k - 1500), str(k) if k < 2000 else f"{k}.25",
                     "" if k % 7 == 0 else str(k), f"w{k}" if k == 2999 else f"{k}.5",
                     ["traversed", "stuck", "side_exit"][k % 3], "",
                     ["a, b", 'say "hi"', "two\nlines", "Ünïcødé"][k % 4],
                     "" if k < 2500 else "x"])
    path = tmp_path / "t.csv"
    with open(path, "w", newline="", encoding="utf-8") as f:
        csv.writer(f, lineterminator="\n").writerows(rows)
    got = beamsim.read_csv(path)
    same(got, reference(path))
    assert [got[c].dtype.kind for c in rows[0]] == ["i", "f", "f", "U", "U", "f", "U", "U"]
    empty = tmp_path / "empty.csv"
    empty.write_text("a,b\n")
    same(beamsim.read_csv(empty), reference(empty))


def test_read_csv_refuses_a_malformed_table(tmp_path):
    path = tmp_path / "bad.csv"
    path.write_text("a,b\n1,2\n3\n4,5\n")
    with pytest.raises(ValueError, match=r"bad\.csv:3: expected 2 fields, got 1"):
        beamsim.read_csv(path)


def test_sweep_beyond_memory_is_refused(h1, tmp_path, monkeypatch):
    """Arrays that would not fit: ValueError before any trial, nothing
    written."""
    monkeypatch.setattr(beamsim, "_CELL_BYTES", 1e15)
    with pytest.raises(ValueError, match="expected trials that fit in memory as columns: "
                                         "90 trials x 30 columns x 1e"):
        beamsim.sweep(h1, trials=3, out=tmp_path / "never")
    assert not os.path.exists(tmp_path / "never")


READ = """
import resource, sys
import beamsim
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t = beamsim.read_csv(sys.argv[1])
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print((after - before) * 1024, sum(a.nbytes for a in t.values()))
"""


@pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                    reason="AddressSanitizer's quarantine keeps freed memory resident")
def test_read_csv_holds_the_arrays(h1, tmp_path):
    """Reading a sweep's trials.csv of 120,000 rows grows the peak resident
    memory of the process by at most 1.25 times the arrays' own bytes and
    4 MB: the rows are not held as Python objects (which took 1.6 KB a row,
    six times the arrays)."""
    cli("sweep", h1, "--trials", 4000, "--set", "integration.max_steps=20", "--limit",
        "mat_rows=1", "--quiet", "--out", tmp_path / "s")
    p = subprocess.run([sys.executable, "-c", READ, str(tmp_path / "s" / "trials.csv")],
                       capture_output=True, text=True, check=True)
    grown, arrays = map(int, p.stdout.split())
    assert arrays > 120000 * 200
    assert grown <= 1.25 * arrays + 4e6, (grown, arrays)
