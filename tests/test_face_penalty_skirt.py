"""Penalty on quadratic skirts through the face-integrated penalty law (issue 23; reference_solver/face_penalty.py).

48 x 6 x 1 skirt (n_theta, n_z, n_r), default loads, lambda to 0.8 in 8 increments, hex20r and tet10 (wedge15 and
hex20 measured too; the penalty method used to be refused on 8-/6-node faces):
- the table reactions carry N at every increment (1e-9);
- full contact (lambda 0.5): the per-azimuth sums of the table forces equal the face-weighted Lagrange law's
  within 2 % of the peak (measured 0.10 / 0.50 / 0.52 / 0.97 % hex20r / tet10 / wedge15 / hex20: the penalty's
  compliance);
- liftoff onset (the first table node without an active integration point in its support) within 0.5 % of the
  same law on 8-node hexahedra (hex8i) on the same mesh (measured 0.6012 against hex20r 0.6031, tet10 0.5995,
  wedge15 0.5996, hex20 0.6031; the nodal penalty on hex8i, first node with a positive gap: 0.5895).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from deckbridge.model import load
from deckbridge.solve import condense_model, solve_system
from reference_solver.face_penalty import face_weighted

MESH = ["mesh.n_theta=48", "mesh.n_z=6", "mesh.n_r=1", "steps.lambda_max=0.8", "steps.increments=8",
        "outputs.vtu=false"]


def _solve(element, method, face=False):
    m = load(None, [f"mesh.element={element}", *MESH])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh, system = condense_model(m)
    _, summary, sol = solve_system(m, mesh, face_weighted(system) if face else system, method, recover=False)
    return m, system.problem, summary, sol


def _azimuth_sums(p, sol, lam):
    tab = p.contact_surface == "table"
    xyz = p.nodes[p.contact_nodes[tab]]
    th = np.round(np.degrees(np.arctan2(xyz[:, 1], xyz[:, 0])) % 360, 6)
    i = int(np.flatnonzero((sol.step == 2) & np.isclose(sol.load_factor, lam))[0])
    f = sol.force[i][tab]
    return np.array([f[th == a].sum() for a in np.unique(th)]), sol.closed[i][tab]


@pytest.fixture(scope="module")
def hex8_onset():
    return _solve("hex8i", "penalty", face=True)[2]["liftoff_load_factor"]


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_penalty_on_a_quadratic_skirt(element, hex8_onset):
    m, p, summary, sol = _solve(element, "penalty")
    assert p.contact_weighting == "face"
    tab = p.contact_surface == "table"
    np.testing.assert_allclose(sol.force[:, tab].sum(axis=1), m.loads.N, rtol=1e-9)
    pen, closed = _azimuth_sums(p, sol, 0.5)
    assert closed.all()                                               # corners included
    _, pl, _, sl = _solve(element, "lagrange")
    lag, _ = _azimuth_sums(pl, sl, 0.5)
    assert np.abs(pen - lag).max() <= 0.02 * np.abs(lag).max()
    assert summary["liftoff_load_factor"] == pytest.approx(hex8_onset, rel=5e-3)


def test_run_pairs_ccx_f2f_with_the_face_penalty_only_when_frictionless(tmp_path):
    """``run --with-ccx`` adds ``reference/f2f`` (deckbridge/reference_f2f.py) when the f2f deck was written and the
    model has no friction (the face-integrated law is frictionless); the series is the face law's solve."""
    from deckbridge.dialects import DIALECTS
    from deckbridge.reference_f2f import f2f_series, wants_f2f
    m = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "outputs.vtu=false", "steps.increments=4"])
    (tmp_path / f"{m.name}_ccx_f2f.inp").write_text("")
    assert wants_f2f(m, [DIALECTS["calculix"]], tmp_path)
    assert not wants_f2f(m, [DIALECTS["mystran"]], tmp_path)
    assert not wants_f2f(m, [DIALECTS["calculix"]], tmp_path / "none")
    f = load(None, ["contact.tangential=friction", "contact.friction=0.3"])
    (tmp_path / f"{f.name}_ccx_f2f.inp").write_text("")
    assert not wants_f2f(f, [DIALECTS["calculix"]], tmp_path)
    mesh, system = condense_model(m)
    res = f2f_series(m, mesh, system, "job")
    t = res.table
    assert set(t.method) == {"f2f"} and set(t.source) == {"reference"}
    assert t[(t.surface == "table") & (t.step == 1)].force_n.sum() == pytest.approx(m.loads.N, rel=1e-9)
    assert res.wall is not None and not res.wall.empty
