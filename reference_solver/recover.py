"""Whole-model fields of every state of a load path: displacements in one solve, stresses per state.

Units: displacements [m], stresses [Pa], tension > 0. Voigt order of every stress array here:
(xx, yy, zz, xy, yz, zx) (:mod:`reference_solver.stress`).
"""

from __future__ import annotations

import numpy as np

from .condense import CondensedSystem
from .kinematics import elasticity_matrix, von_mises
from .path import Solution
from .stress import extrapolate_to_nodes, nodal_sums


def path_fields(system: CondensedSystem, sol: Solution, rows=None) -> np.ndarray:
    """Global displacements (m, n, 3) [m] of the Solution's rows ``rows`` (default every row, i.e.
    the end of step 1 and every increment of step 2), recovered with ONE call of
    :meth:`CondensedSystem.recover` (one multi-right-hand-side back substitution)."""
    idx = np.arange(sol.step.size) if rows is None else np.asarray(rows, np.int64)
    x = sol.u if sol.retained_u is None else sol.retained_u     # friction: normal + tangential dofs
    return system.recover(x[idx], sol.coeffs[idx]).reshape(idx.size, -1, 3)


def states_stress(p, U: np.ndarray) -> list[dict]:
    """Stresses of m states with nodal displacements ``U`` (m, n, 3) [m] of problem ``p``; the
    Gauss-point strain operator of each element block is built once (``Element.gauss_strain_operator``).

    Per state a dict: ``cell`` (ne, 6) volume average of the element's stress by its own quadrature,
    sum_g sigma_g w_g det J_g / sum_g w_g det J_g [Pa] (so that sum over a layer of elements of cell
    sigma_zz x volume is the layer's integral of sigma_zz, as in the stiffness); ``cell_von_mises``
    (ne,) von Mises of that average [Pa]; ``nodal`` (n, 6): Gauss values extrapolated to the element
    nodes (``Element.extrapolation``, an estimate) and averaged, unweighted, over the elements sharing
    the node [Pa]; ``nodal_von_mises`` (n,) von Mises of the nodal average [Pa]. Nodes no element
    touches get 0. Elements are numbered block by block (``p.blocks``).
    """
    D = elasticity_matrix(p.E, p.nu)
    n = p.nodes.shape[0]
    ops = []
    for b in p.blocks:
        xyz = p.nodes[b.cells]
        w = b.element.volume_weights(xyz)
        ops.append((b, b.element.gauss_strain_operator(xyz, p.E, p.nu), w / w.sum(axis=1, keepdims=True)))
    out = []
    for u in np.asarray(U, float).reshape(-1, n, 3):
        cells, total, count = [], np.zeros((n, 6)), np.zeros(n)
        for b, op, w in ops:
            g = np.einsum("egij,ej->egi", op, u[b.cells].reshape(len(b.cells), -1)) @ D.T   # (ne, ng, 6)
            cells.append(np.einsum("eg,egk->ek", w, g))
            t, c = nodal_sums(extrapolate_to_nodes(g, b.element), b.cells, n)
            total += t
            count += c
        cell = np.concatenate(cells)
        with np.errstate(invalid="ignore", divide="ignore"):
            nodal = np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], 0.0)
        out.append({"cell": cell, "cell_von_mises": von_mises(cell),
                    "nodal": nodal, "nodal_von_mises": von_mises(nodal)})
    return out
