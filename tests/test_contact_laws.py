"""The reference solver's contact-law interface, its one load-path driver and its one onset module, on a
block standing on a rigid table (the solver alone: nothing from deckbridge).

Anchors: the exact Lagrange solution (the augmented Lagrangian must reach it at any epsilon), the force
balance of the applied load (a throw-away law added by the "Add a contact law" checklist of
ARCHITECTURE.md), and the rigid-block kern for the onset ordering.
"""

from __future__ import annotations

from dataclasses import fields
from functools import lru_cache

import numpy as np
import pytest

import reference_solver as rs
from reference_solver import augmented
from reference_solver.laws import ContactLaw, register

E, NU = 2.1e11, 0.3
L, H = 0.4, 0.3


def _block(n=4, nz=3, dz=0.0):
    """A steel block L x L x H on the table z = 0 (bottom nodes: contact rows, x/y springs), loaded on its top
    face at its centre: N (compression), T (shear along x), M (about y: lifts one edge)."""
    x, z = np.linspace(0, L, n + 1), np.linspace(0, H, nz + 1)
    X, Y, Z = np.meshgrid(x, x, z, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), Z.ravel() + dz * X.ravel()], 1)
    idx = lambda i, j, k: (i * (n + 1) + j) * (nz + 1) + k  # noqa: E731
    I, J, K = (a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), np.arange(nz), indexing="ij"))
    hexes = np.stack([idx(I, J, K), idx(I + 1, J, K), idx(I + 1, J + 1, K), idx(I, J + 1, K),
                      idx(I, J, K + 1), idx(I + 1, J, K + 1), idx(I + 1, J + 1, K + 1), idx(I, J + 1, K + 1)], 1)
    bottom = np.flatnonzero(np.isclose(Z.ravel(), 0.0))
    top = np.flatnonzero(np.isclose(Z.ravel(), H))
    h = L / n
    w = np.where(np.isclose(X.ravel()[bottom] % L, 0), 0.5, 1.0) * np.where(np.isclose(Y.ravel()[bottom] % L, 0), 0.5, 1.0)
    area = w * h * h
    K_bulk = E / (3 * (1 - 2 * NU))
    nb = bottom.size
    return rs.Problem(
        nodes=nodes, hexes=hexes, E=E, nu=NU, contact_nodes=bottom, contact_normals=np.tile([0.0, 0.0, 1.0], (nb, 1)),
        contact_area=area, contact_k=0.1 * K_bulk * area / (H / nz), contact_clearance=np.zeros(nb),
        contact_surface=np.array(["table"] * nb), spring_nodes=np.concatenate([bottom, bottom]),
        spring_dirs=np.vstack([np.tile([1.0, 0, 0], (nb, 1)), np.tile([0, 1.0, 0], (nb, 1))]),
        spring_k=np.full(2 * nb, 1.0e7), ref_point=np.array([L / 2, L / 2, H]), coupling_nodes=top,
        coupling_weights=np.ones(top.size),
        loads={"N": (0, 0, -1.0e6, 0, 0, 0), "T": (1.0e4, 0, 0, 0, 0, 0), "M": (0, 5.0e5, 0, 0, 0, 0)})


@lru_cache(maxsize=None)
def _system(dz=0.0):
    return rs.condense(_block(dz=dz))


def _path(system, method, kf=1.0, **kw):
    return rs.solve_path(system, method, kf, lambda_max=1.0, increments=8, recover=False, **kw)


@pytest.mark.parametrize("dz", [0.0, 0.05])                 # a second, held-out geometry: a sheared block
@pytest.mark.parametrize("kf", [0.1, 1.0, 10.0, 100.0])
def test_augmented_lagrangian_reaches_the_exact_lagrange_forces_at_any_epsilon(kf, dz):
    system = _system(dz)
    lag, aug = _path(system, "lagrange"), _path(system, "augmented", kf)
    peak = np.abs(lag.force).max()
    assert lag.liftoff_load_factor is not None                 # the path goes past liftoff
    assert np.abs(aug.force - lag.force).max() <= 1e-6 * peak  # at every lambda of the path
    assert np.array_equal(aug.closed, lag.closed)
    assert aug.penetration.max() <= aug.penetration_tol
    assert aug.penetration_tol == pytest.approx(augmented.PENETRATION * np.sqrt(np.median(system.problem.contact_area)))
    assert aug.liftoff_load_factor == pytest.approx(lag.liftoff_load_factor, rel=1e-9)   # tracked on the exact problem
    assert aug.augmentations[aug.step == 2][1:].min() >= 1
    pen = _path(system, "penalty", kf)                          # plain penalty at the same epsilon is off
    assert np.abs(pen.force - lag.force).max() > 100 * np.abs(aug.force - lag.force).max()


def test_augmented_cost_falls_as_epsilon_grows():
    system = _system()
    counts = [int(_path(system, "augmented", kf).augmentations.sum()) for kf in (1.0, 100.0)]
    assert counts[1] < counts[0]


def test_one_driver_records_named_increments_and_the_registry_lists_the_laws():
    assert rs.METHODS == ("penalty", "lagrange", "augmented")
    assert {f.name for f in fields(rs.Increment)} == {"step", "index", "load_factor", "coeffs", "state"}
    sol = _path(_system(), "penalty", targets=[0.5, 0.0])       # up and back down: any law follows targets
    assert sol.load_factor.tolist() == pytest.approx([0, 0] + [0.5 * j / 8 for j in range(1, 9)]
                                                      + [0.5 - 0.5 * j / 8 for j in range(1, 9)])
    assert np.allclose(sol.force[1], sol.force[-1], atol=1e-9 * np.abs(sol.force).max())   # path-independent
    with pytest.raises(rs.ReferenceSolverError, match="method = 'coulomb'"):
        _path(_system(), "coulomb")


@pytest.mark.parametrize("method", ["penalty", "lagrange", "augmented"])
def test_one_onset_module_exact_onset_agrees_with_bisection(method):
    system = _system()
    exact = _path(system, method)
    bis = _path(system, method, onset="bisection", liftoff_tol=1e-7)
    assert exact.liftoff_method == "path-following" and bis.liftoff_method == "bisection"
    assert bis.liftoff_load_factor - 1e-7 <= exact.liftoff_load_factor <= bis.liftoff_load_factor + 1e-6
    assert exact.liftoff_row == bis.liftoff_row
    xy = system.problem.nodes[system.problem.contact_nodes, :2]
    groups = [np.flatnonzero(np.isclose(xy[:, a], v)) for a in (0, 1) for v in (0.0, L)]   # the four edges
    lam, g = rs.section_onset(system, exact, groups)
    assert g is not None and exact.liftoff_load_factor <= lam <= 1.0
    below = rs.solve_path(system, method, lambda_max=lam - 1e-6, increments=1, onset="off", recover=False)
    above = rs.solve_path(system, method, lambda_max=lam + 1e-6, increments=1, onset="off", recover=False)
    edge = groups[g]
    assert not np.all(below.gap[-1, edge] > 0) and np.all(above.gap[-1, edge] > 0)


def test_a_throw_away_law_added_by_the_checklist_runs_through_the_driver():
    """ARCHITECTURE.md, "Add a contact law": (1) a ContactLaw subclass with name, algorithms and increment
    (track and arrays optional), (2) register it; nothing else in the solver changes. A bilateral (tied)
    law: every row held at gap 0, whatever the sign of its force."""

    @register
    class TiedLaw(ContactLaw):
        name, algorithms = "tied", ("direct",)

        def increment(self, prev, coeffs, guess=None, depth=0):
            u = -self.c0
            return self.checked(u, self.system.Sc @ u - self.load(coeffs), np.ones(u.size, bool), 0)

    try:
        system = _system()
        sol = _path(system, "tied")
        p = system.problem
        assert sol.method == "tied" and sol.algorithm == "direct" and sol.liftoff_load_factor is None
        assert (sol.force < 0).any()                              # it pulls where the others lift off
        for i in range(sol.step.size):                            # force balance: contact + springs = -applied
            f = (sol.force[i][:, None] * p.contact_normals).sum(0) + (sol.spring_force[i][:, None] * p.spring_dirs).sum(0)
            applied = sol.coeffs[i] @ np.array([p.loads[n] for n in system.case_names])
            assert np.allclose(f, -applied[:3], atol=1e-6 * 1.0e6)
    finally:
        rs.LAWS.pop("tied")
