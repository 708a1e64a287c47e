"""Coulomb friction with the stop past liftoff (issue 14, observation 2): the Lagrange path's tangential forces
change by more than T per increment and not monotonically (the table's Sum F_t,x drops from lambda 0.7 to
0.8, then rises). Physical, not an artefact of the Lagrange solve: the penalty method with a growing
stiffness (k_factor 1e2, 1e3, 1e4; k_t follows k) converges to the same path.

The table's friction balances T and the stop's push on the compressed side (the wall's Poisson growth under
the local axial stress, docs/friction.md); as the contact patch shrinks towards tipping, that push moves
and changes with the discrete contact set. Compared, per node: the whole contact force (normal and
tangential of every surface at the node), unique also where the stop-table split is not.

Measured (24 x 6 x 2, mu = 0.3, lambda to 1 in 10 increments, each increment solved whole by both
methods): per increment the largest |difference| of a node / the largest Lagrange force, its mean over the
path: horizontal k 1e2 0.21, 1e3 0.049, 1e4 0.025; vertical 0.17, 0.036, 0.005 (asserted). The largest
single increment is not monotone in k (horizontal 0.81, 0.098, 0.175; with 20 increments 0.81, 0.33,
0.063): where a node closes or opens within an increment, the path-dependent friction state follows the
order in which the discrete contact set changes, and penalty with a finite k changes it at slightly other
loads. Sum F_t,x of the table [kN], lambda 0.7 / 0.8 / 0.9: see docs/friction.md.
"""

from functools import lru_cache

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem

MODEL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=2", "contact.friction=0.3", "contact.tangential=friction"]


@lru_cache(maxsize=None)
def _system():
    model = load(None, MODEL)
    p = build_problem(model, build_mesh(model))
    return model, p, rs.condense(p)


def _whole(p, sol):
    """(increments, nodes, 3) whole contact force of every contact node [N] (table + stop rows summed)."""
    w = sol.force[:, :, None] * p.contact_normals[None] + sol.tangential_force
    nodes, idx = np.unique(p.contact_nodes, return_inverse=True)
    out = np.zeros((len(sol.step), nodes.size, 3))
    np.add.at(out, (slice(None), idx), w)
    return out


def test_penalty_with_growing_stiffness_converges_to_the_lagrange_path_with_the_stop():
    model, p, system = _system()
    lag = rs.solve_path(system, "lagrange", recover=False)
    ref = _whole(p, lag)
    tab = p.contact_surface == "table"
    errs = []
    for k in (1e2, 1e3, 1e4):
        pen = rs.solve_path(system, "penalty", k, recover=False)
        assert np.allclose(pen.load_factor, lag.load_factor)
        got = _whole(p, pen)
        # per increment: largest |difference| of a node / the largest of the Lagrange forces; then the path mean
        eh = np.abs(got[..., :2] - ref[..., :2]).max(axis=(1, 2)) / np.abs(ref[..., :2]).max()
        ez = np.abs(got[..., 2] - ref[..., 2]).max(axis=1) / np.abs(ref[..., 2]).max(axis=1)
        errs.append((eh.mean(), ez.mean()))
    assert errs[0][0] > errs[1][0] > errs[2][0] and errs[0][1] > errs[1][1] > errs[2][1], errs
    assert errs[2][0] <= 0.04 and errs[2][1] <= 0.01, errs
    # the jump: Sum F_t,x of the table is not monotone in lambda, in both methods alike
    sx_lag = lag.tangential_force[:, tab, 0].sum(axis=1)
    sx_pen = pen.tangential_force[:, tab, 0].sum(axis=1)
    T = lag.load_factor * model.loads.T
    step2 = lag.step == 2
    assert np.all(np.sign(np.diff(sx_lag[step2])) == np.sign(np.diff(sx_pen[step2])))
    assert np.any(np.diff(sx_lag[step2]) < 0)                         # far above T d(lambda) = 0.1 T:
    assert np.max(np.abs(np.diff(sx_lag[step2]))) > 0.5 * model.loads.T
    # balance: table friction + stop normal = T lambda (x), whatever the split
    stop = ~tab
    fx = sx_lag + (lag.force[:, stop, None] * p.contact_normals[None, stop])[..., 0].sum(axis=1)
    # round-off of a sum of forces up to ~1 MN: 1e-9 of the largest contact force (2.1e-4 N was seen at lambda = 1
    # on one machine's BLAS, above 1e-9 T = 2e-4 N; the balance itself is exact)
    assert np.allclose(fx, T, rtol=0, atol=1e-9 * np.abs(lag.force).max())


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_with_the_stop_a_load_cycle_stays_in_the_cone_and_dissipates(method):
    """Corner rules in use (penalty 'both', Lagrange 'stop' first, the stop opening and closing): loading to
    lambda = 1 and back to 0, no row's |F_t| exceeds mu F_n beyond round-off, the dissipation of every
    increment is >= 0, rows slip on the way, and the cycle leaves a residual tangential state."""
    model, p, system = _system()
    mu = model.contact.friction
    sol = rs.solve_path(system, method, 1e3 if method == "penalty" else 1.0, recover=False, targets=[1.0, 0.0])
    tn = np.linalg.norm(sol.tangential_force, axis=2)
    assert np.all(tn <= mu * np.maximum(sol.force, 0.0) * (1 + 1e-9) + 1e-9 * tn.max())
    assert np.all(sol.dissipation >= -1e-12 * sol.dissipation.max()) and sol.dissipation.max() > 0
    assert np.any(sol.stick_status == "slip")
    first = int(np.flatnonzero(sol.step == 1)[-1])                   # N alone, before the cycle
    assert sol.load_factor[-1] == 0.0
    assert np.abs(sol.tangential_force[-1] - sol.tangential_force[first]).max() > 1e-2 * tn.max()
    assert np.any(np.isin(sol.stick_status[:, p.contact_surface == "stop"], ["open"]))
