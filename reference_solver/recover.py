"""Whole-model fields of every state of a load path: displacements in one solve, stresses per state.

Units: displacements [m], stresses [Pa], tension > 0. Voigt order of every stress array here:
(xx, yy, zz, xy, yz, zx) (:mod:`reference_solver.stress`).
"""

from __future__ import annotations

import numpy as np

from .condense import CondensedSystem
from .elements import elasticity_matrix, shape_gradients, von_mises
from .path import Solution
from .stress import GAUSS, extrapolate_to_corners, gauss_strain_operator, nodal_average


def path_fields(system: CondensedSystem, sol: Solution, rows=None) -> np.ndarray:
    """Global displacements (m, n, 3) [m] of the Solution's rows ``rows`` (default every row, i.e.
    the end of step 1 and every increment of step 2), recovered with ONE call of
    :meth:`CondensedSystem.recover` (one multi-right-hand-side back substitution)."""
    idx = np.arange(sol.step.size) if rows is None else np.asarray(rows, np.int64)
    x = sol.u if sol.retained_u is None else sol.retained_u     # friction: normal + tangential dofs
    return system.recover(x[idx], sol.coeffs[idx]).reshape(idx.size, -1, 3)


def states_stress(p, U: np.ndarray) -> list[dict]:
    """Stresses of m states with nodal displacements ``U`` (m, n, 3) [m] of problem ``p``; the
    Gauss-point strain operator is built once (:func:`stress.gauss_strain_operator`).

    Per state a dict: ``cell`` (ne, 6) volume average of the element's stress by its own 2 x 2 x 2
    quadrature, sum_g sigma_g det J_g / sum_g det J_g [Pa] (so that sum over a layer of elements of
    cell sigma_zz x volume is the layer's integral of sigma_zz, as in the stiffness); ``cell_von_mises``
    (ne,) von Mises of that average [Pa]; ``nodal`` (n, 6): Gauss values extrapolated to
    the corners (trilinear fit, an estimate) and averaged, unweighted, over the elements sharing the node
    [Pa]; ``nodal_von_mises`` (n,) von Mises of the nodal average [Pa]. Nodes no element touches get 0.
    """
    xyz = p.nodes[p.hexes]
    op = gauss_strain_operator(xyz, p.E, p.nu, p.element)                   # (ne, 8, 6, 24)
    detj = np.stack([np.linalg.det(np.einsum("ia,eaj->eij", shape_gradients(xi), xyz)) for xi in GAUSS], 1)
    w = detj / detj.sum(axis=1, keepdims=True)                               # (ne, 8) quadrature weights
    D = elasticity_matrix(p.E, p.nu)
    out = []
    for u in np.asarray(U, float).reshape(-1, p.nodes.shape[0], 3):
        g = np.einsum("egij,ej->egi", op, u[p.hexes].reshape(len(p.hexes), 24)) @ D.T   # (ne, 8, 6)
        cell = np.einsum("eg,egk->ek", w, g)
        nodal, count = nodal_average(extrapolate_to_corners(g), p.hexes, p.nodes.shape[0])
        nodal = np.where(count[:, None] > 0, nodal, 0.0)
        out.append({"cell": cell, "cell_von_mises": von_mises(cell),
                    "nodal": nodal, "nodal_von_mises": von_mises(nodal)})
    return out
