"""Coulomb friction of the reference solver (penalty, contact.tangential = friction) against CalculiX on the
project's own node-to-surface penalty deck with ``*FRICTION`` (mu, stick slope k_t / A_ccx), small mesh, no
radial stop, past liftoff with rows slipping (issue 14: within 3 % of the peak sigma_N, 5 % of the peak |tau|).

Measured (24 x 6 x 1 mesh, distributing top, 2-core dev box, ccx 2.20), max |difference| / peak per increment:
- mu = 0.3 (every row sticks up to lambda = 1): sigma_N <= 0.03 %, |F_t| <= 0.13 %;
- mu = 0.1, lambda 0.6-0.9 (8-21 rows slipping): sigma_N <= 0.03 %, |F_t| <= 0.05 % (this test);
  at lambda = 1 ccx cuts its increment back (1.9 -> 2.0 in steps of 0.025) and lands 67 % away from the
  reference (peak sigma_N -99 MPa against -73 MPa, both balancing N and M + T H), while the reference
  does not move with the increments (10 or 40: 0.02 %): not resolved, left out of the test.
- With the default inner stop: tests/test_friction_stop_vs_ccx.py (the penalty corner rule 'both', as ccx).
"""

import shutil

import numpy as np
import pytest

from deckbridge.dialects import DIALECTS
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.readers.calculix import n2f_tangential_force
from deckbridge.render import render_all
from deckbridge.solve import condense_model, solve_system

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.stop.side=none",
         "contact.friction=0.1", "contact.tangential=friction", "steps.lambda_max=0.9", "steps.increments=9"]


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx (CalculiX) not installed")
def test_penalty_friction_matches_ccx_node_to_surface_friction_past_liftoff(tmp_path):
    model = load(None, MODEL)
    calculix = DIALECTS["calculix"]
    render_all(model, tmp_path / "decks", names=["calculix"])
    deck = tmp_path / "ccx" / f"{model.name}_ccx_penalty.inp"
    deck.parent.mkdir()
    shutil.copyfile(tmp_path / "decks" / deck.name, deck)
    assert "*FRICTION" in deck.read_text() and "TYPE=SPRING1" not in deck.read_text()
    calculix.run_module().run(deck, timeout_s=300)

    mesh, system = condense_model(model, build_mesh(model))
    _, summary, sol = solve_system(model, mesh, system, "penalty", recover=False)
    p = system.problem
    tab = np.flatnonzero(p.contact_surface == "table")
    nodes = p.contact_nodes[tab] + 1
    ccx = read(deck.with_suffix(".frd"), model=model)
    ccx = ccx[ccx.surface == "table"]
    ft_ccx = n2f_tangential_force(deck.with_suffix(".dat"), model)
    lift = summary["liftoff_load_factor"]
    past = [i for i in np.flatnonzero(sol.step == 2) if sol.load_factor[i] > lift]
    assert len(past) >= 3 and np.any(sol.stick_status[past[-1]] == "slip")     # past liftoff, rows slipping
    worst = []
    for i in past:
        lam = float(sol.load_factor[i])
        sig_ref = -sol.force[i, tab] / p.contact_area[tab]
        sig_ccx = ccx[np.isclose(ccx.load_factor, lam)].set_index("node").sigma_n_pa.reindex(nodes).to_numpy()
        worst.append((lam, np.abs(sig_ref - sig_ccx).max() / np.abs(sig_ref).max()))
        ft_ref = np.linalg.norm(sol.tangential_force[i, tab], axis=1)
        t = 1.0 + lam / model.steps.lambda_max
        at = ft_ccx[min(ft_ccx, key=lambda k: abs(k - t))]
        ft_c = np.array([at.get(int(n), 0.0) for n in nodes])
        worst[-1] += (np.abs(ft_ref - ft_c).max() / ft_ref.max(), int(np.sum(sol.stick_status[i] == "slip")))
    assert all(s <= 0.03 and t <= 0.05 for _, s, t, _ in worst), worst
