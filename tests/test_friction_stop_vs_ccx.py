"""Coulomb friction WITH the radial stop (issue 14): the reference solver's penalty method against CalculiX on
the project's own node-to-surface ``*FRICTION`` deck, small mesh, past liftoff, rows slipping and the stop
closed (the acceptance: within 3 % of the peak sigma_N and 5 % of the peak |tau|).

A base node on both the table and the stop (a corner node) gets, in both, the stop's normal force along the
radial and the table's friction in both tangent axes of the table (the penalty corner rule 'both',
docs/friction.md). The deck's stop master faces are centred on the skirt's azimuths, so that ccx's stop normal
at each slave is radial, as the reference's (on face corners ccx took either face's normal, 7.5 deg off:
|tau| then differed by up to 6 %, antisymmetric about the load plane).

Measured (24 x 6 x 1, mu = 0.3, lambda to 1 in 10 increments, 2-core dev box, ccx 2.20, ~1 s): max |difference|
/ peak per increment: sigma_N table rows <= 0.03 %, stop rows <= 0.22 %, |F_t| <= 0.05 %. With the former corner
rule (no table friction along the stop's normal) |tau| differed by 20-55 %; with the rule 'both' and the stop
faces' corners at the slaves by up to 6.2 % (docs/friction.md, section 3)."""

import shutil

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.dialects.calculix.reader import n2f_tangential_force
from deckbridge.solve import condense_model, solve_system
from ccx_job import ccx_penalty_job

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.stop.side=inner",
         "contact.friction=0.3", "contact.tangential=friction", "steps.lambda_max=1.0", "steps.increments=10"]


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx (CalculiX) not installed")
def test_penalty_friction_with_the_stop_matches_ccx_past_liftoff(tmp_path):
    model = load(None, MODEL)
    deck = ccx_penalty_job(model, tmp_path)
    text = deck.read_text()
    assert "*FRICTION" in text and "MASTER_STOP" in text.upper() and "TYPE=SPRING1" not in text

    mesh, system = condense_model(model, build_mesh(model))
    _, summary, sol = solve_system(model, mesh, system, "penalty", recover=False)
    p = system.problem
    rows = {s: np.flatnonzero(p.contact_surface == s) for s in ("table", "stop")}
    ccx = read(deck.with_suffix(".frd"), model=model)
    ft_ccx = n2f_tangential_force(deck.with_suffix(".dat"), model)
    lift = summary["liftoff_load_factor"]
    past = [i for i in np.flatnonzero(sol.step == 2) if sol.load_factor[i] > lift]
    assert len(past) >= 3
    assert any(np.any(sol.stick_status[i] == "slip") for i in past)                     # rows slipping
    assert all(np.sum(sol.force[i, rows["stop"]] > 0) >= 3 for i in past)              # the stop closed
    tab, nodes = rows["table"], p.contact_nodes[rows["table"]] + 1
    worst = []
    for i in past:
        lam = float(sol.load_factor[i])
        at_lam = ccx[np.isclose(ccx.load_factor, lam)]
        sig = []
        for s, r in rows.items():
            ref = -sol.force[i, r] / p.contact_area[r]
            got = at_lam[at_lam.surface == s].set_index("node").sigma_n_pa.reindex(p.contact_nodes[r] + 1).to_numpy()
            sig.append(np.abs(ref - np.nan_to_num(got)).max() / np.abs(ref).max())
        ft_ref = np.linalg.norm(sol.tangential_force[i, tab], axis=1)
        t = 1.0 + lam / model.steps.lambda_max
        at = ft_ccx[min(ft_ccx, key=lambda k: abs(k - t))]
        ft_c = np.array([at.get(int(n), 0.0) for n in nodes])
        worst.append((lam, *sig, np.abs(ft_ref - ft_c).max() / ft_ref.max()))
    assert all(st <= 0.03 and ss <= 0.03 and t <= 0.05 for _, st, ss, t in worst), worst
    # the corner nodes do carry table friction along the stop's normal (the radial), as in ccx
    corner = np.isin(p.contact_nodes[tab], p.contact_nodes[rows["stop"]])
    th = np.radians(mesh.table.theta_deg)
    fr = sol.tangential_force[past[-1], tab, 0] * np.cos(th) + sol.tangential_force[past[-1], tab, 1] * np.sin(th)
    assert np.abs(fr[corner]).max() > 0.05 * np.abs(np.linalg.norm(sol.tangential_force[past[-1], tab], axis=1)).max()
