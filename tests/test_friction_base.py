"""Coulomb friction under N alone (issue 14, step 1) against two independent truths on a small mesh.

Under the axial load alone the compressed wall wants to grow radially (Poisson: hoop and thickness
strain nu |sigma_zz| / E). A sticking base holds it back, so the table carries a self-equilibrated set
of radial friction forces (the stop, when closed, pushing outwards at the inner nodes): no net shear,
yet |F_t| up to mu F_n at some nodes (docs/friction.md, observation 1). Two closed checks:

- nu = 0: no lateral strain, the exact solution is uniform compression (a linear field, which the
  C3D8I elements reproduce): every tangential force and the stop force vanish, sigma_N = -N / A;
- mu = 1e3 (Lagrange): nothing slips, so the base is bonded: the contact forces equal the reactions of
  an independent linear problem, the same mesh with every table node fixed in x, y and z (the reference
  solver's element assembly and load distribution, no contact code), to 1e-6 of the largest reaction.
"""

from functools import lru_cache

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import reference_solver as rs
from reference_solver.assembly import assemble_stiffness
from reference_solver.loads import distributing_forces
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem

SMALL = ("mesh.n_theta=24", "mesh.n_z=6", "contact.tangential=friction")


@lru_cache(maxsize=None)
def _system(*sets):
    model = load(None, list(SMALL + sets))
    p = build_problem(model, build_mesh(model))
    return model, p, rs.condense(p)


def _step1(system, method):
    """The end of step 1 (N alone) of a friction path; step 2 ramps nothing."""
    sol = rs.solve_path(system, method, base={"N": 1.0}, ramp={"T": 0.0}, lambda_max=1.0, increments=1,
                        recover=False)
    return int(np.flatnonzero(sol.step == 1)[-1]), sol


@pytest.mark.parametrize("stop", ["inner", "none"])
@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_without_poisson_n_alone_leaves_no_tangential_force(method, stop):
    model, p, system = _system("mesh.n_r=2", "material.nu=0", "load_introduction=kinematic", "contact.friction=0.3",
                               f"contact.stop.side={stop}")
    i, sol = _step1(system, method)
    tab = p.contact_surface == "table"
    N = model.loads.N
    assert np.abs(sol.tangential_force[i]).max() <= 1e-9 * N / tab.sum()
    assert np.abs(sol.force[i, ~tab]).max(initial=0.0) <= 1e-9 * N / tab.sum()      # the stop carries nothing
    assert abs(sol.force[i, tab].sum() - N) <= 1e-9 * N
    nonzero = _system("mesh.n_r=2", "load_introduction=kinematic", "contact.friction=0.3", f"contact.stop.side={stop}")
    j, with_nu = _step1(nonzero[2], method)
    assert np.abs(with_nu.tangential_force[j]).max() > 1e-3 * N / tab.sum()          # nu = 0.3: friction works


def _bonded_reactions(p):
    """Reactions (n_table, 3) [N] of the table nodes, fixed in x, y, z, under N (distributing coupling)."""
    K = assemble_stiffness(p.nodes, p.hexes, p.E, p.nu, p.element).tocsc()
    f = np.zeros((p.n_nodes, 3))
    f[p.coupling_nodes] = distributing_forces(p.nodes[p.coupling_nodes], p.coupling_weights, p.ref_point,
                                              np.asarray(p.loads["N"][:3]), np.asarray(p.loads["N"][3:]))
    fixed_nodes = p.contact_nodes[p.contact_surface == "table"]
    fixed = (3 * fixed_nodes[:, None] + np.arange(3)).ravel()
    free = np.setdiff1d(np.arange(3 * p.n_nodes), fixed)
    u = np.zeros(3 * p.n_nodes)
    u[free] = spla.spsolve(K[free][:, free], f.ravel()[free])
    return (K[fixed] @ u - f.ravel()[fixed]).reshape(-1, 3)


@pytest.mark.parametrize("stop, radius, closed", [("none", "null", None), ("inner", "null", True),
                                                  ("outer", "null", True), ("inner", "1.48", False)])
def test_large_friction_is_a_bonded_base(stop, radius, closed):
    """With a stop touching the wall the bonded base pushes the corner nodes onto it (the stop takes their
    radial force, Lagrange rule 'stop first'); with a stop 5 mm off the wall it stays open and the
    table's friction holds the corner nodes radially."""
    model, p, system = _system("mesh.n_r=2", "contact.friction=1000", f"contact.stop.side={stop}",
                               f"contact.stop.radius={radius}")
    i, sol = _step1(system, "lagrange")
    tab = np.flatnonzero(p.contact_surface == "table")
    whole = sol.force[i][:, None] * p.contact_normals + sol.tangential_force[i]     # contact force per row [N]
    per_node = np.zeros((p.n_nodes, 3))
    np.add.at(per_node, p.contact_nodes, whole)                                      # table + stop at a node
    expected = _bonded_reactions(p)
    assert np.all(sol.stick_status[i][tab] == "stick")
    if closed is not None:                   # the stop closed (it takes the corner's radial force) or open
        assert np.all((sol.force[i, p.contact_surface == "stop"] > 0) == closed)
    got = per_node[p.contact_nodes[tab]]
    assert np.abs(got - expected).max() <= 1e-6 * np.abs(expected).max()
    assert np.abs(expected[:, :2]).max() > 1e-3 * np.abs(expected[:, 2]).max()      # the base does hold it back
