"""ccx's tangential contact forces on a renumbered import (issue 14 x issue 15): the node-to-surface
penalty deck with ``*FRICTION`` on the user's ids (large, non-consecutive, file order shuffled) gives the
same |F_t| per node as on the parametric numbering, once ids are mapped back; the reader maps a deck id
to its node's ccx slave area through the mesh, not through ``id - 1``."""

import shutil

import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.dialects.calculix.reader import n2f_tangential_force
from test_import_mesh import _renumbered
from ccx_job import ccx_penalty_job

SMALL = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=4", "steps.lambda_max=0.8",
         "contact.stop.side=none", "contact.friction=0.1", "contact.tangential=friction", "name=F"]


def _ccx_tangential(model, folder):
    deck = ccx_penalty_job(model, folder)
    return n2f_tangential_force(deck.with_suffix(".dat"), model)


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx (CalculiX) not installed")
def test_renumbered_import_gives_the_same_ccx_tangential_forces(tmp_path):
    par = load(None, SMALL)
    me = build_mesh(par)
    f, nid, *_ = _renumbered(me, tmp_path / "renum.inp", 5, (7, 90001), (5, 3001))
    imp = load(None, SMALL + [f"mesh.file={f}", "mesh.sets={base: BASE, top: TOP}"])
    a = _ccx_tangential(par, tmp_path / "par")
    b = _ccx_tangential(imp, tmp_path / "imp")
    back = dict(zip(nid.tolist(), range(1, me.n_nodes + 1)))
    assert set(a) == set(b) and len(a) >= 4
    peak = max(max(v.values(), default=0.0) for v in a.values())
    assert peak > 0
    for t in a:
        got = {back[n]: v for n, v in b[t].items()}
        assert set(got) == set(a[t])
        assert max((abs(got[n] - a[t][n]) for n in a[t]), default=0.0) <= 1e-6 * peak
