"""Penalty friction on 8-node table faces (issue 23) settles at the stiff k-factors of ``run``'s penalty verdict and
approaches the Lagrange answer as k grows (hex20r 16 x 2 x 1, distributing top, default N, T, M, no stop, mu 0.3,
CalculiX's dual basis: reference_solver/friction_face.py).

Before: the friction Newton (friction_newton.py) asked for a residual of 1e-10 |f| on the weighted system, whose
evaluation error eps (|S~| |x~| + |f~|) is ~1e-9 |f~| there (|S~| |x~| ~ 4e6 |f~|): every Newton ran its 60 steps,
the slip thresholds' fixed point (friction.solve_increment) sat at a rounding noise of ~2e-9 above its 1e-11 and
every increment was cut back: k-factor 1000 had not finished in 400 s (1 / 10 / 100: 2 / 4 / 1 s). Measured now:
k-factor 1000 / 10000 in 0.6 / 2.1 s, the largest nodal table force 1.5708 / 1.6117 MN against Lagrange's 1.6170 MN
(2.9 % / 0.33 %: ~1/k), Sum F_t = T and Sum F_n = N.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import reference_solver as rs
from deckbridge.model import load
from deckbridge.solve import condense_model


def test_penalty_friction_on_8_node_faces_settles_and_approaches_lagrange():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, ["mesh.element=hex20r", "mesh.n_theta=16", "mesh.n_z=2", "mesh.n_r=1", "outputs.vtu=false",
                        "contact.tangential=friction", "contact.friction=0.3", "contact.stop.side=none"])
        _, system = condense_model(m)                      # refused before the fix (solve.check_solvable)
    assert system.problem.contact_weighting == "face-dual"
    path = dict(base={"N": 1.0}, ramp={"T": 1.0, "M": 1.0}, lambda_max=1.0, increments=4, recover=False)
    exact = rs.solve_path(system, "lagrange", **path)
    peak = np.abs(exact.force[-1]).max()
    err = {}
    for kf in (1000.0, 10000.0):
        sol = rs.solve_path(system, "penalty", kf, **path)
        assert sol.load_factor[-1] == 1.0
        assert sol.force[-1].sum() == pytest.approx(m.loads.N, rel=1e-9)                       # Sum F_n = N
        ft = sol.tangential_force[-1].sum(axis=0)                   # table on the skirt, global [N]
        assert np.hypot(ft[0], ft[1]) == pytest.approx(m.loads.T, rel=1e-6)                    # |Sum F_t| = T
        assert sol.friction_check(None, 0.3)["violations"] == 0
        err[kf] = abs(np.abs(sol.force[-1]).max() - peak) / peak
    assert err[10000.0] < 0.01 and err[10000.0] < 0.2 * err[1000.0]     # measured 0.0033, 0.029
