"""The faster Lagrange friction solve (issue 14) reaches the same increments as the plain method.

The semi-smooth Newton now starts from the path's estimate of each increment and takes a closed row
slipping along its own force as sticking in its iterates (reference_solver.friction_ssn). Neither may
change the solution of an increment: every increment of a path past liftoff (table friction, radial
stop) is solved again from the same converged state with the plain iteration of the earlier solver
(from the previous increment, then from the energy-descent penalty predictor) and must agree.
"""

from functools import lru_cache

import numpy as np

import reference_solver as rs
import reference_solver.friction as friction
import reference_solver.friction_ssn as fssn
from deckbridge.model import load
from deckbridge.solve import build_problem

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1", "contact.tangential=friction", "contact.friction=0.3"]


@lru_cache(maxsize=None)
def _system():
    model = load(None, MODEL)
    return model, rs.condense(build_problem(model))


def test_every_lagrange_increment_matches_the_plain_semi_smooth_newton(monkeypatch):
    model, system = _system()
    pairs = []
    solve_fast = fssn.solve_lagrange_increment

    def both(sysf, f, prev, mu, max_disp, **kw):
        st = solve_fast(sysf, f, prev, mu, max_disp, **kw)
        with monkeypatch.context() as m:
            m.setattr(fssn, "WRONG_WAY_STICK", False)
            predictor = kw.get("predictor") or (lambda kp, ktp: friction.solve_increment(
                sysf, "penalty", f, prev, kp, 1e-12 * kp, ktp, mu, max_disp, tol=friction.PREDICTOR_TOL))
            ref = solve_fast(sysf, f, prev, mu, max_disp, predictor=predictor)
        pairs.append((st, ref))
        return st

    monkeypatch.setattr(friction, "solve_lagrange_increment", both)
    sol = rs.solve_path(system, "lagrange", lambda_max=1.0, increments=10, recover=False)
    assert sol.liftoff_load_factor is not None
    past_liftoff = 0
    for st, ref in pairs:
        scale = np.abs(ref.x).max()
        assert np.abs(st.x - ref.x).max() <= 1e-8 * scale
        assert np.abs(st.p - ref.p).max() <= 1e-8 * np.abs(ref.p).max()
        assert np.array_equal(st.active, ref.active) and np.array_equal(st.slip, ref.slip)
        past_liftoff += int(not st.active.all())
    assert len(pairs) >= 15 and past_liftoff >= 5          # the path's increments and its liftoff bisection
