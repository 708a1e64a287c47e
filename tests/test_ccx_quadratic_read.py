"""deckbridge's own ccx reader on the quadratic-face decks (issue 23; deckbridge/dialects/calculix/face_rows.py).

Mortar (``*_ccx_lagrange``): table sigma_N = -D^-T r, ccx's own multipliers (D_ab = int psi_a N_b dA of its dual
basis, reference_solver.face_weights.dual_mortar; until round 4 the hat basis of the reference's default law) of
the slave nodes' consistent forces r = RF_z. Independent truths: the multipliers' resultant sum_a sigma_a d_a
(d = int T N dA from dual_mortar's row sums, not the reader's table areas) balances the applied N, ccx's law
(lambda >= 0: no read row in tension), and the through-wall sigma_N (face-consistent: -Sum F / Sum a, F the nodal
forces of each field and a = int N_i dA) of the read table against the reference solver's
Face-to-face (``*_ccx_f2f``): table sigma_N = -CPRESS, equal to the .frd read directly as
tests/test_ccx_quadratic_mortar.py does."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

import reference_solver as rs
from ccx_job import ccx_job
from deckbridge.dialects.calculix.result_files import _frd_blocks
from deckbridge.errors import InputError
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.numbering.skirt import mesh_node_ids
from deckbridge.quantities import sigma_n_wall
from deckbridge.readers import read
from deckbridge.readers._contact_law import check_contact_law
from reference_solver.elements import element_type
from reference_solver.face_weights import dual_mortar, face_shares, hat_mortar, surface_faces

TOL = 0.02                      # of the reference's peak |sigma_N| (issue 23)
MOMENT_MESH = ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1", "contact.stop.side=none", "steps.increments=5"]


def _table_faces(mesh):
    on = np.zeros(mesh.n_nodes, bool)
    on[mesh.table.nodes] = True
    return surface_faces((rs.ElementBlock(element_type(mesh.element), mesh.hexes),), on)


def _shares(mesh) -> dict[int, float]:
    """int psi_a dA = d_a [m^2] of every table node (node id -> share; psi ccx's dual basis): the resultant of a
    unit multiplier."""
    share = np.zeros(mesh.n_nodes)
    for ftype, conn in _table_faces(mesh):
        np.add.at(share, conn.ravel(), dual_mortar(ftype, mesh.nodes[conn]).sum(axis=2).ravel())
    return dict(zip(mesh_node_ids(mesh, mesh.table.nodes).tolist(), share[mesh.table.nodes].tolist()))


def _field_wall(rows: pd.DataFrame, mesh, mortar=hat_mortar) -> pd.Series:
    """Through-wall sigma_N [Pa] per azimuth of a table whose sigma_N are the multipliers of a pressure field
    p = sum sigma_a Phi_a in the basis of ``mortar`` (hat_mortar: the reference's default; dual_mortar: ccx's):
    -Sum F / Sum a over the azimuth's table nodes, F = int N_i p dA the field's consistent node force (element
    mortar matrices int Phi_a N_i dA) and a = int N_i dA; exact for a pressure constant through the wall."""
    tab = rows[rows["surface"] == "table"]
    p = np.zeros(mesh.n_nodes)
    idx = {int(n): k for n, k in zip(mesh_node_ids(mesh, np.arange(mesh.n_nodes)), range(mesh.n_nodes))}
    p[[idx[int(n)] for n in tab["node"]]] = tab["sigma_n_pa"].to_numpy(float)
    force, share = np.zeros(mesh.n_nodes), np.zeros(mesh.n_nodes)
    for ftype, conn in _table_faces(mesh):
        np.add.at(force, conn.ravel(), np.einsum("fab,fa->fb", mortar(ftype, mesh.nodes[conn]), p[conn]).ravel())
        np.add.at(share, conn.ravel(), face_shares(ftype, mesh.nodes[conn]).ravel())
    k = [idx[int(n)] for n in tab["node"]]
    g = pd.DataFrame({"t": np.round(tab["theta_deg"].to_numpy(float), 6), "f": force[k], "a": share[k]})
    g = g.groupby("t").sum()
    return g["f"] / g["a"]


@pytest.mark.parametrize("element", ["tet10", "hex20"])
def test_mortar_read_table_balances_and_matches_the_reference_lagrange(tmp_path, element):
    """Measured 24 x 3 x 1 (default loads, 5 increments): the read table's resultant sum sigma_a d_a equals N at
    every state (ccx's equilibrium; asserted to 1e-6), no read row tensile; through-wall sigma_N of the two
    pressure fields (:func:`_field_wall`: the nodal forces, basis-free) in full contact (lambda 0 .. 0.4) against the
    reference's default (hat) Lagrange: tet10 <= 0.86 %, hex20 <= 0.005 % of the reference peak (hex20 1.41 % with
    the HRZ top weights of round 4, docs/mortar_stop.md); quantities.sigma_n_wall (-Sum force / Sum area, the rows'
    own areas: d for ccx, hat for the reference) tet10 <= 0.57 %, hex20 <= 0.73 % (round 4: 0.58 / 0.75 %; read in the hat basis on hat areas: 1.71 %,
    0.07 %; with HRZ areas and -M^-1 r: 2.39 % and 5.21 %)."""
    from deckbridge.solve import condense_model, contact_table, solve_system
    model = load(None, [f"mesh.element={element}"] + MOMENT_MESH)
    inp = ccx_job(model, tmp_path, "lagrange")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")              # the quadratic-mesh 'unverified' warning
        mesh, system = condense_model(model)
        _, _, sol = solve_system(model, mesh, system, "lagrange")
    ccx = read(inp.parent, fmt="calculix", model=model, mesh=mesh)
    ref = contact_table(system.problem, mesh, sol)
    share = _shares(mesh)
    assert set(ccx["method"]) == {"mortar"}
    compared = 0
    for (step, inc), c in ccx.groupby(["step", "increment"]):
        a = c["node"].map(share).to_numpy(float)
        resultant = -float(np.sum(c["sigma_n_pa"].to_numpy(float) * a))
        assert resultant == pytest.approx(model.loads.N, rel=1e-6), (step, inc)
        assert c["sigma_n_pa"].max() <= 1e-6 * c["sigma_n_pa"].abs().max(), (step, inc)     # ccx's lambda >= 0
        lam = float(c["load_factor"].iloc[0])
        r = ref[(ref.step == step) & np.isclose(ref.load_factor, lam)]
        r = r[r.increment == r.increment.max()]
        if not (r["status"] == "closed").all():
            continue
        d = (_field_wall(c, mesh, dual_mortar) - _field_wall(r, mesh)).abs().max() / r["sigma_n_pa"].abs().max()
        assert d <= TOL, (step, lam, d)
        d = (sigma_n_wall(c) - sigma_n_wall(r)).abs().max() / r["sigma_n_pa"].abs().max()
        assert d <= TOL, (step, lam, d)
        compared += 1
    assert compared >= 3                              # lambda 0, 0.2, 0.4


def test_f2f_read_table_is_minus_cpress(tmp_path):
    """hex20r 24 x 3 x 1 face-to-face job (master: a C3D8 ring, no master node under a slave node): every read
    table row is -CPRESS of the .frd (0 where ccx printed none), state by state, and the job reads to lambda 1, with
    the model or without it (a face half in contact hands ccx's CPRESS to a node 1.9 mm open at lambda 0.8: judged
    on its faces' gaps, law_gap_m)."""
    model = load(None, ["mesh.element=hex20r"] + MOMENT_MESH)
    inp = ccx_job(model, tmp_path, "f2f")
    ccx = read(inp, fmt="calculix", model=model)
    assert set(ccx["method"]) == {"f2f"}
    assert ccx.loc[ccx.step == 2, "load_factor"].max() == pytest.approx(1.0)
    mesh = build_mesh(model)
    ids = mesh_node_ids(mesh, mesh.table.nodes)
    _, blocks = _frd_blocks(inp.with_suffix(".frd"))
    direct = [(b["step"], np.array([b["values"].get(int(i), np.zeros(4))[3] for i in ids]))
              for b in blocks if b["name"] == "CONTACT"]
    states = ccx.groupby(["step", "increment"], sort=True)
    assert len(direct) == len(states) == 6
    for (step, cpress), ((s, _), rows) in zip(direct, states):
        got = rows.set_index("node").loc[ids, "sigma_n_pa"].to_numpy(float)
        assert s == step
        np.testing.assert_allclose(got, -cpress, rtol=1e-12, atol=0.0)
    bare = read(inp, fmt="calculix")                 # no model: the deck's slave lines map the nodes
    np.testing.assert_array_equal(bare["sigma_n_pa"].to_numpy(), ccx["sigma_n_pa"].to_numpy())


def _rows(sigma, gap, **extra) -> pd.DataFrame:
    n = len(sigma)
    return pd.DataFrame({"source": "ccx", "method": "mortar", "step": 1, "increment": 1, "node": np.arange(1, n + 1),
                         "surface": "table", "theta_deg": np.arange(n) * 7.5, "r": 1.5, "sigma_n_pa": sigma,
                         "gap_m": gap, **extra})


def test_contact_law_judges_a_projected_row_by_the_solvers_pressure():
    """A projected pressure may overshoot to tension at a closed row next to the contact edge (ccx mortar hex20r
    24 x 3 x 1 at lambda 0.6: +4 % of the peak); judged on the solver's own pressure (law_sigma_pa) it passes, and
    a flipped solver pressure still fails."""
    sigma = np.array([-10e6, -5e6, 0.4e6, -2e6])
    gap = np.zeros(4)
    with pytest.raises(InputError, match="tension in a closed contact"):
        check_contact_law(_rows(sigma, gap), "x")
    own = np.array([-10e6, -5e6, -0.1e6, -2e6])
    out = check_contact_law(_rows(sigma, gap, law_sigma_pa=own), "x")
    assert "law_sigma_pa" not in out.columns and out["sigma_n_pa"].tolist() == sigma.tolist()
    with pytest.raises(InputError, match="tension in a closed contact"):
        check_contact_law(_rows(sigma, gap, law_sigma_pa=-own), "x")
