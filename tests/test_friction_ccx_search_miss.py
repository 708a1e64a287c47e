"""ccx's state at lambda = 1.0 (24 x 6 x 1, no stop, mu = 0.1; tests/test_friction_vs_ccx.py) is no second
solution of the reference's discrete friction problem (docs/friction.md, section 4, hypothesis a).

ccx's table displacements (its ``.dat``, 6 digits) are put into the reference's penalty equations of the
increment 0.9 -> 1.0, from the reference's state at 0.9 (which ccx matches to 6e-4): the residual is
0.77 of the largest normal force (0.0025 at 0.9, the print precision). The reference's Newton, started
from ccx's state, goes back to the reference's own state (2e-11). Independent part: ccx's displacements and
the residual of the equilibrium S x = f + R(x) with the penalty and Coulomb laws evaluated at them."""

import shutil

import numpy as np
import pytest

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.dialects.calculix.result_files import _dat_blocks
from deckbridge.solve import condense_model, solve_system
from deckbridge.tangent_springs import follow_springs
from reference_solver.friction import State, solve_increment
from reference_solver.friction_newton import _laws, _residual, newton
from ccx_job import ccx_penalty_job

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.stop.side=none",
         "contact.friction=0.1", "contact.tangential=friction", "steps.lambda_max=1.1", "steps.increments=11"]


def _coulomb(sysf, k, k_open, kt, mu, prev, f, x):
    """Residual / max normal force of the increment's equations at x, slip threshold mu p(x) (Coulomb)."""
    z, s_ref, fr = np.zeros_like(k), prev.x[sysf.tdofs], sysf.rows
    p, *_ = _laws(x, sysf, k, k_open, kt, np.full(fr.size, np.inf), z, prev.t, s_ref)
    cap = mu * np.maximum(p[fr], 0.0)
    p, _, _, t, *_ = _laws(x, sysf, k, k_open, kt, cap, z, prev.t, s_ref)
    return np.abs(_residual(sysf, f, x, p, t)).max() / np.abs(p).max(), cap


@pytest.mark.skipif(shutil.which("ccx") is None, reason="ccx (CalculiX) not installed")
def test_ccx_state_at_the_search_miss_is_no_solution_of_the_reference_problem(tmp_path):
    model = load(None, MODEL)
    deck = ccx_penalty_job(model, tmp_path)

    mesh, sysf = condense_model(model, build_mesh(model))
    _, _, sol = solve_system(model, mesh, sysf, "penalty", recover=False)
    sysf = follow_springs(sysf, "penalty", 1.0).with_corner("both")
    p = sysf.problem
    k, kt, mu = p.contact_k, p.contact_kt[sysf.rows], p.friction
    k_open, max_disp = p.k_open_ratio * k, p.max_displacement or p.length_scale()
    cb, cr = sysf.coeffs({"N": 1.0}), sysf.coeffs({"T": 1.0, "M": 1.0})
    nf = sysf.rows.size
    st = State(x=np.zeros(sysf.S.shape[0]), p=np.zeros(p.n_contacts), t=np.zeros((nf, 2)),
               active=p.contact_clearance <= 0, slip=np.zeros(nf, bool))
    states = [solve_increment(sysf, "penalty", sysf.fhat @ cb, st, k, k_open, kt, mu, max_disp)]
    for j in range(1, 11):                                     # the path's increments, lambda = 0.1 ... 1.0
        states.append(solve_increment(sysf, "penalty", sysf.fhat @ (cb + 0.1 * j * cr), states[-1], k, k_open, kt,
                                      mu, max_disp))
    row = int(np.flatnonzero((sol.step == 2) & np.isclose(sol.load_factor, 1.0))[0])
    np.testing.assert_allclose(states[-1].x, sol.retained_u[row], atol=1e-9 * np.abs(states[-1].x).max())

    dirs = np.zeros((sysf.S.shape[0], 3))                      # global direction and node of each retained dof
    node = np.zeros(sysf.S.shape[0], np.int64)
    dirs[:p.n_contacts], node[:p.n_contacts] = p.contact_normals, p.contact_nodes
    for i, j in enumerate(sysf.rows):
        dirs[sysf.tdofs[i]], node[sysf.tdofs[i]] = sysf.tdir[i], p.contact_nodes[j]
    blocks = [b for b in _dat_blocks(deck.with_suffix(".dat")) if b["set"] == "NTABLE"]

    def ccx_x(lam):
        b = [b for b in blocks if abs(b["time"] - (1.0 + lam / 1.1)) < 1e-6][-1]
        return np.einsum("ij,ij->i", np.array([b["values"][int(n) + 1] for n in node]), dirs)

    res = {}
    for lam, prev, ref in ((0.9, states[8], states[9]), (1.0, states[9], states[10])):
        f = sysf.fhat @ (cb + lam * cr)
        x = ccx_x(lam)
        res[lam] = (np.abs(x - ref.x).max() / np.abs(ref.x).max(), _coulomb(sysf, k, k_open, kt, mu, prev, f, x)[0])
    assert res[0.9][0] < 2e-3 and res[0.9][1] < 0.02, res                 # ccx = reference to its print precision
    assert res[1.0][0] > 0.01 and res[1.0][1] > 0.3, res                   # ccx's state: far off the equations
    # the reference's Newton (Coulomb fixed point on the thresholds), started from ccx's state at 1.0
    f, prev, x = sysf.fhat @ (cb + cr), states[9], ccx_x(1.0)
    cap = _coulomb(sysf, k, k_open, kt, mu, prev, f, x)[1]
    for _ in range(100):
        new_st = newton(sysf, f, k, k_open, kt, cap, np.zeros_like(k), prev.t, prev.x[sysf.tdofs], x, max_disp)
        x, new = new_st.x, mu * np.where(new_st.active[sysf.rows], np.maximum(new_st.p[sysf.rows], 0.0), 0.0)
        if np.abs(new - cap).max() <= 1e-11 * np.abs(new).max():
            break
        cap = new
    assert np.abs(x - states[10].x).max() <= 1e-8 * np.abs(states[10].x).max()   # back to the reference's state
    assert _coulomb(sysf, k, k_open, kt, mu, prev, f, x)[0] < 1e-9
