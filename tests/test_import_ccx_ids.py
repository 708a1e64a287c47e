"""A renumbered, reordered import of the JAR mesh through the whole job with ccx (issue 15 on main's
decks): the node-to-surface penalty deck, the mortar deck, their readers and the ccx ParaView series
map the user's ids (large, non-consecutive, file order shuffled) back onto the same nodes, so ccx's
answers on the two numberings agree (a real solver's output on both)."""

import numpy as np
import pytest

from deckbridge.job import run_job
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from test_import_mesh import _renumbered

SMALL = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=4", "name=J"]


@pytest.mark.skipif(__import__("shutil").which("ccx") is None, reason="ccx not installed")
def test_renumbered_import_gives_ccx_the_same_answers_through_the_job(tmp_path):
    import meshio

    par = load(None, SMALL)
    me = build_mesh(par)
    f, nid, _, on, _ = _renumbered(me, tmp_path / "renum.inp", 3, (11, 40001), (3, 7001))
    imp = load(None, SMALL + [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}"])
    quiet = lambda s: None  # noqa: E731
    run_job(par, tmp_path / "par", with_ccx=True, echo=quiet)
    run_job(imp, tmp_path / "imp", with_ccx=True, echo=quiet)
    back = dict(zip(nid.tolist(), range(1, me.n_nodes + 1)))
    a = read(tmp_path / "par" / "ccx", model=par)
    b = read(tmp_path / "imp" / "ccx", model=imp)
    assert set(b.node) <= set(nid.tolist())
    b = b.assign(node=b.node.map(back))
    j = a.merge(b, on=["method", "step", "increment", "node", "surface"], suffixes=("_p", "_i"))
    assert len(j) == len(a) == len(b) and set(j.method) == {"penalty", "mortar", "f2f"}
    for _, s in j.groupby(["method", "step", "increment"]):
        assert np.abs(s.sigma_n_pa_p - s.sigma_n_pa_i).max() <= 1e-6 * np.abs(s.sigma_n_pa_p).max()
    # ccx ParaView series: point k of the import is node on[k] of the parametric mesh
    for job in ("J_ccx_penalty", "J_ccx_lagrange"):
        last = sorted((tmp_path / "par" / "ccx").glob(f"{job}_0*.vtu"))[-1].name
        p = meshio.read(tmp_path / "par" / "ccx" / last)
        q = meshio.read(tmp_path / "imp" / "ccx" / last)
        np.testing.assert_array_equal(q.point_data["node_id"], nid[on])
        u = p.point_data["displacement_m"]
        np.testing.assert_allclose(q.point_data["displacement_m"], u[on], rtol=0, atol=1e-6 * np.abs(u).max())
    # the job's numbers: load path of every source (readers) and the reference base-wall sigma_zz
    import json

    import pandas as pd
    lp = [json.loads((tmp_path / d / "summary.json").read_text())["load_path"] for d in ("par", "imp")]
    assert set(lp[0]) == set(lp[1]) and {"ccx/mortar", "ccx/penalty"} <= set(lp[0])
    for src, v in lp[0].items():
        for key, x in v.items():
            x, y = np.asarray(x, float), np.asarray(lp[1][src][key], float)
            assert np.abs(x - y).max() <= 1e-6 * max(np.abs(x).max(), 1e-30), (src, key)
    for method in ("penalty", "lagrange"):
        w = [pd.read_csv(tmp_path / d / f"reference_{method}" / "wall_stress.csv") for d in ("par", "imp")]
        assert len(w[0]) == len(w[1]) > 0
        for col in ("szz_inner_pa", "szz_outer_pa", "szz_mean_pa"):
            assert np.abs(w[0][col] - w[1][col]).max() <= 1e-6 * np.abs(w[0][col]).max(), (method, col)
