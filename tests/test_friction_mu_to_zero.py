"""Lagrange Coulomb friction with mu -> 0 tends to the frictionless Lagrange path (issue 26).

The independent truth is the frictionless Lagrange solve: the same model with the tangential load on
circumferential springs (``contact.tangential: springs``, no friction code) whose stiffness k_t -> 0.
Its sigma_N differs from the limit linearly in k_t (measured on 24 x 6 x 1: 1.3e-4 / 1.3e-5 / 4e-6 /
2.7e-6 of the peak at k_t = 1e5 / 1e4 / 3e3 / 2e3 N/m; at 1e3 the frictionless path finds no
equilibrium at lambda = 0.1), so the limit is extrapolated from k_t = 2e3 and 3e3 N/m.

Before the fix one corner row (node 12, stop open) of the last increment carried 8.9 kN of radial table
friction against mu F_n = 6e-8 N, and sigma_N there was 1.4e-2 of the peak off the frictionless path:
the semi-smooth Newton took a closed row whose increment points along its force as sticking
(``friction_ssn.WRONG_WAY_STICK``) and, at s = s_ref to round-off (t . ds = +5e-16), accepted the stick
equation rho_t ds = 0 with |t| far above mu p. A root of those iterate equations is now accepted only
where the plain Alart-Curnier equations vanish too.
"""

import numpy as np

import reference_solver as rs
from deckbridge.model import load
from deckbridge.solve import build_problem

SMALL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]      # default inner stop, touching
MU = 1e-12


def _path(sets):
    model = load(None, SMALL + sets)
    return rs.solve_path(rs.condense(build_problem(model)), "lagrange", lambda_max=model.steps.lambda_max,
                         increments=model.steps.increments, recover=False)


def test_lagrange_friction_with_vanishing_mu_is_the_frictionless_lagrange_path():
    sol = _path(["contact.tangential=friction", f"contact.friction={MU}"])
    ft = np.linalg.norm(sol.tangential_force, axis=2)                    # (increments, rows) [N]
    fn = np.maximum(sol.force, 0.0)
    floor = 1e-9 * max(ft.max(), fn.max())                               # round-off of the forces
    assert np.all(ft <= MU * fn * (1 + 1e-9) + floor), ft.max()
    assert sol.friction_check(None, MU)["violations"] == 0
    near = [_path(["contact.tangential=springs", f"contact.penalty.k_tangent={kt}"]) for kt in (2e3, 3e3)]
    for r in near:
        np.testing.assert_allclose(r.load_factor, sol.load_factor, rtol=0, atol=1e-12)
    limit = near[0].sigma_n - 2.0 * (near[1].sigma_n - near[0].sigma_n)   # linear in k_t, at k_t = 0
    peak = np.abs(limit).max()
    err = np.abs(sol.sigma_n - limit).max(axis=1) / peak                  # per increment
    assert err.max() <= 1e-6, err
