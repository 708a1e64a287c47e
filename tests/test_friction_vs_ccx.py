"""Coulomb friction of the reference solver (penalty, contact.tangential = friction) against CalculiX on the
project's own node-to-surface penalty deck with ``*FRICTION`` (mu, stick slope k_t / A_ccx), small mesh, no
radial stop, past liftoff with rows slipping (issue 14: within 3 % of the peak sigma_N, 5 % of the peak |tau|).

Measured (24 x 6 x 1 mesh, distributing top, 2-core dev box, ccx 2.20), max |difference| / peak per increment:
- mu = 0.3 (every row sticks up to lambda = 1): sigma_N <= 0.03 %, |F_t| <= 0.13 %;
- mu = 0.1, lambda 0.6-1.1 (8-21 rows slipping): sigma_N <= 0.03 %, |F_t| <= 0.05 % (this test), except
  at lambda = 1.0, where ccx is 67 % off (peak sigma_N -99 MPa against -73 MPa). The cause is ccx's
  node-to-surface contact search, not the problem (docs/friction.md, section 4): ccx generates no contact
  element for the inner node at theta = 225 deg although it penetrates the table by 1.47 mm (its own
  displacements), so that node carries no force where the penalty law gives k x 1.47 mm = 299 kN. ccx's
  state is then asymmetric about the load plane (the model is symmetric), and it is no equilibrium of the
  reference's discrete problem (residual 0.77 of the largest normal force; the reference's Newton started
  from ccx's state goes back to the symmetric one to 2e-11). Fixed increments (40, no cutback) give the
  same -99 MPa; at lambda = 1.1 ccx has the node back and agrees to 0.03 % again.
  This test checks both: agreement at every other increment, and at lambda = 1.0 that ccx's state breaks
  ccx's own penalty law at a penetrating node with no force (against its own displacements), while every
  node that does have a contact element obeys it.
- With the default inner stop: tests/test_friction_stop_vs_ccx.py (the penalty corner rule 'both', as ccx).
"""

import shutil

import numpy as np
import pytest

from deckbridge import quantities as Q
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.dialects.calculix.reader import n2f_tangential_force
from deckbridge.solve import condense_model, solve_system
from ccx_job import ccx_penalty_job

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.stop.side=none",
         "contact.friction=0.1", "contact.tangential=friction", "steps.lambda_max=1.1", "steps.increments=11"]
SEARCH_MISS = 1.0      # the load factor at which ccx's contact search drops a penetrating node (docstring)


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx (CalculiX) not installed")
def test_penalty_friction_matches_ccx_node_to_surface_friction_past_liftoff(tmp_path):
    model = load(None, MODEL)
    deck = ccx_penalty_job(model, tmp_path)
    assert "*FRICTION" in deck.read_text() and "TYPE=SPRING1" not in deck.read_text()

    mesh, system = condense_model(model, build_mesh(model))
    ref_table, summary, sol = solve_system(model, mesh, system, "penalty", recover=False)
    p = system.problem
    tab = np.flatnonzero(p.contact_surface == "table")
    nodes = p.contact_nodes[tab] + 1
    ccx = read(deck.with_suffix(".frd"), model=model)
    ccx = ccx[ccx.surface == "table"]
    ft_ccx = n2f_tangential_force(deck.with_suffix(".dat"), model)
    lift = summary["liftoff_load_factor"]
    past = [i for i in np.flatnonzero(sol.step == 2) if sol.load_factor[i] > lift]
    assert len(past) >= 5 and np.any(sol.stick_status[past[-1]] == "slip")     # past liftoff, rows slipping
    worst, miss = [], None
    for i in past:
        lam = float(sol.load_factor[i])
        at_lam = ccx[np.isclose(ccx.load_factor, lam)].set_index("node").reindex(nodes)
        sig_ref = -sol.force[i, tab] / p.contact_area[tab]
        sig_ccx = at_lam.sigma_n_pa.to_numpy()
        ft_ref = np.linalg.norm(sol.tangential_force[i, tab], axis=1)
        t = 1.0 + lam / model.steps.lambda_max
        at = ft_ccx[min(ft_ccx, key=lambda k: abs(k - t))]
        ft_c = np.array([at.get(int(n), 0.0) for n in nodes])
        row = (lam, np.abs(sig_ref - sig_ccx).max() / np.abs(sig_ref).max(), np.abs(ft_ref - ft_c).max() / ft_ref.max(),
               int(np.sum(sol.stick_status[i] == "slip")))
        if np.isclose(lam, SEARCH_MISS):
            miss = (row, at_lam, i)
        else:
            worst.append(row)
    assert all(s <= 0.03 and t <= 0.05 for _, s, t, _ in worst), worst
    # the force-free penetration check (deckbridge.quantities) flags ccx at the miss and nowhere else, and
    # never the reference (whose penalty rows carry k x penetration)
    flags = {round(float(lam), 6): Q.free_penetration(g) for lam, g in ccx[ccx.step == 2].groupby("load_factor")}
    assert [lam for lam, f in flags.items() if f["free_penetration_warn"]] == [SEARCH_MISS]
    assert any(lam > SEARCH_MISS for lam, *_ in worst)                     # agreement again past the miss

    # lambda = 1.0: ccx's contact search leaves a penetrating node without a contact element
    (lam, s_err, _, _), at_lam, i = miss
    assert s_err > 0.3                                                     # still there (else: extend the test)
    k = p.contact_k[tab]
    pen = -at_lam.gap_m.to_numpy()                                         # ccx's own penetration [m]
    f_ccx = -at_lam.sigma_n_pa.to_numpy() * p.contact_area[tab]            # ccx's own normal force [N]
    has = f_ccx > 0
    np.testing.assert_allclose(f_ccx[has], k[has] * pen[has], rtol=1e-3)  # elements present: ccx's law holds
    dropped = ~has & (pen > 0)
    assert dropped.sum() == 1 and pen[dropped][0] > 1e-3                   # penetrates > 1 mm, no force
    fp = flags[SEARCH_MISS]
    assert fp["free_penetration_nodes"] == [int(nodes[dropped][0])]
    assert fp["free_penetration_m"] == pytest.approx(pen[dropped][0], rel=1e-12)
    assert not any(Q.free_penetration(g)["free_penetration_warn"] for _, g in ref_table.groupby("load_factor"))
    th, r = mesh.table.theta_deg, mesh.table.r                             # table rows in the order of tab
    assert np.array_equal(mesh.table.nodes, p.contact_nodes[tab])
    mirror = np.array([np.flatnonzero((np.abs((th + th[j] + 180) % 360 - 180) < 1e-6) & np.isclose(r, r[j]))[0]
                       for j in range(tab.size)])                          # the row mirrored about the load plane
    assert np.all(f_ccx[mirror[dropped]] > 0)                              # ccx: its mirror carries force
    ref_f = sol.force[i, tab]
    np.testing.assert_allclose(ref_f, ref_f[mirror], rtol=1e-6, atol=1e-9 * np.abs(ref_f).max())  # reference symmetric
    assert np.all(ref_f[dropped] > 0)                                      # and closed at the dropped node
