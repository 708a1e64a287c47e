"""Past the overturning load, Lagrange friction reports that the load tips the body over (issue 14): the
iterates run away with rows still sticking (reference_solver.friction_state.Runaway), the path bisects
to the load and reports it as the frictionless path does, not as gross slip.

Closed form (rigid overturning about the outer base edge): lambda_tip (M + T H) = N R_out, i.e.
lambda_tip = 2.7 MN x 1.51 m / (3 MN m + 0.2 MN x 2 m) = 1.19912 with the default loads; Coulomb could carry
T lambda_tip = 240 kN with mu N = 810 kN, so it is not gross slip. On this mesh (36 x 8 x 2, 10 increments)
the bisection's last sub-increment ends in a Runaway: without that branch of the path it read "the friction
iterations do not converge" (checked).
"""

import re

import pytest

import reference_solver as rs
from deckbridge.model import load
from deckbridge.solve import build_problem
from reference_solver.friction import GrossSlip


def _tipping_error(n_theta: int, increments: int):
    """The error of the Lagrange path to lambda 1.5 on n_theta x 8 x 2 (mu = 0.3), and lambda_tip."""
    model = load(None, [f"mesh.n_theta={n_theta}", "mesh.n_z=8", "mesh.n_r=2", "contact.tangential=friction",
                        "contact.friction=0.3"])
    g, ld = model.geometry, model.loads
    lam_tip = ld.N * (g.radius + g.thickness / 2) / (ld.M + ld.T * g.height)
    assert model.contact.friction * ld.N > ld.T * lam_tip                  # Coulomb carries T: not gross slip
    system = rs.condense(build_problem(model))
    with pytest.raises(rs.ReferenceSolverError) as err:
        rs.solve_path(system, "lagrange", lambda_max=1.5, increments=increments, recover=False)
    return err, lam_tip


def test_lagrange_friction_past_the_overturning_load_tips_the_body_over():
    err, lam_tip = _tipping_error(36, 10)
    assert not isinstance(err.value, GrossSlip)
    assert "tips the body over" in str(err.value)
    lam = float(re.search(r"load factor ([0-9.]+)", str(err.value)).group(1))
    assert lam == pytest.approx(lam_tip, rel=2e-4)                         # bisected to SLIDE_TOL (1e-4 x 1.5)


@pytest.mark.parametrize("n_theta, increments", [(32, 8), (32, 10), (32, 12), (40, 8), (40, 10), (40, 12)])
def test_tipping_load_is_bisected_whatever_the_mesh_and_increments(n_theta, increments):
    """Other meshes and increments reach the same tipping load (the cheap part of the sweep in the commit that
    added this). 8 and 12 increments end in a cut-back whose penalty predictor has no bounded equilibrium; 40 x
    8 with 8 increments in a last sub-step whose exact iterates leave the predictor with every row slipping:
    both are runaways that the path bisects, not a tipping (or gross slip) at the unbisected load."""
    err, lam_tip = _tipping_error(n_theta, increments)
    assert not isinstance(err.value, GrossSlip)
    assert "tips the body over" in str(err.value)
    lam = float(re.search(r"load factor ([0-9.]+)", str(err.value)).group(1))
    assert lam == pytest.approx(lam_tip, rel=2e-4)
