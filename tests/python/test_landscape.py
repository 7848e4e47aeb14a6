"""beamsim.landscape against `beamsim landscape SCENE --out DIR`: the passes
as in landscape.json (bit-equal, JSON numbers having 17 digits), the grid as
in landscape.csv (its %.10g text)."""

import json

import numpy as np
import pytest

import beamsim
from conftest import cli


def plain(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, dict):
        return {k: plain(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [plain(x) for x in v]
    return v


@pytest.mark.parametrize("args", [(), ("--resolution", "0.5", "--region", "-20,20,0,70")])
def test_landscape_is_the_cli_landscape(gate, tmp_path, args):
    cli("landscape", gate, *args, "--out", tmp_path)
    kw = {"resolution": 0.5, "region": (-20, 20, 0, 70)} if args else {}
    L = beamsim.landscape(gate, **kw)
    with open(tmp_path / "landscape.json") as f:
        j = json.load(f)
    for key in ("grid", "start", "far_y", "lowest_pass", "barriers"):
        assert plain(L[key]) == j[key], key
    rows = (tmp_path / "landscape.csv").read_text().splitlines()
    names = rows[0].split(",")
    ny, nx = L["e_total"].shape
    assert len(rows) - 1 == nx * ny
    for k in (0, 1, nx + 3, len(rows) // 2, len(rows) - 2):
        j_, i = divmod(k, nx)
        value = {"x": L["x"][i], "y": L["y"][j_], "e_beam": L["e_beam"][j_, i],
                 "e_prop": L["e_prop"][j_, i], "e_total": L["e_total"][j_, i]}
        for b in range(L["theta"].shape[0]):
            value[f"theta{b + 1}"] = L["theta"][b, j_, i]
        assert ",".join("%.10g" % value[n] for n in names) == rows[k + 1]
    # load reads both files of the directory.
    d = beamsim.load(tmp_path)
    assert d["landscape.json"] == j
    assert np.array_equal(np.unique(d["landscape"]["x"]), np.unique(np.round(L["x"], 9)))


def test_bad_resolution(gate):
    with pytest.raises(ValueError, match="--resolution"):
        beamsim.landscape(gate, resolution=-1)
