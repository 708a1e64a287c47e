"""Load introduction at a reference point: distributing (RBE3-like) nodal forces, rigid-body modes.

Distributing rule (RBE3 / Abaqus *DISTRIBUTING, weighted least squares): with weights w_i and
positions r_i relative to the weighted centroid c, the force F and the moment M_c = M + (ref - c) x F
go to the nodes as f_i = w_i F / sum(w) + w_i (a x r_i), where a = J^-1 M_c and
J = sum_i w_i (|r_i|^2 I - r_i r_i^T). Then sum f_i = F and sum (x_i - ref) x f_i = M exactly.
"""

from __future__ import annotations

import numpy as np

from .errors import ReferenceSolverError


def distributing_forces(xyz: np.ndarray, weights: np.ndarray, ref: np.ndarray,
                        force: np.ndarray, moment: np.ndarray) -> np.ndarray:
    """Nodal forces (nt, 3) [N] statically equivalent to ``force`` and ``moment`` at ``ref``: f_i = w_i F / sum w
    + w_i (a x r_i), r_i from the weighted centroid, a from J a = the moment about it (J = sum w_i (|r_i|^2 I -
    r_i r_i^T)). ``weights`` may hold zero or negative entries (the consistent shares of 8-/6-node faces) with a
    positive sum; CalculiX's ``*COUPLING, *DISTRIBUTING`` spreads a load the same way (measured to the printed
    digits with those shares)."""
    xyz, w = np.asarray(xyz, float), np.asarray(weights, float)
    force, moment = np.asarray(force, float), np.asarray(moment, float)
    c = (w[:, None] * xyz).sum(axis=0) / w.sum()
    r = xyz - c
    m_c = moment + np.cross(np.asarray(ref, float) - c, force)
    J = np.einsum("i,ij->", w, r * r) * np.eye(3) - np.einsum("i,ij,ik->jk", w, r, r)
    f = np.outer(w / w.sum(), force)
    if np.any(m_c != 0):
        if np.linalg.cond(J) > 1e12:
            raise ReferenceSolverError(
                "distributing coupling: the coupling nodes are collinear and cannot carry a moment")
        a = np.linalg.solve(J, m_c)
        f += w[:, None] * np.cross(a, r)
    return f


def rigid_modes(xyz: np.ndarray, ref: np.ndarray, length: float = 1.0) -> np.ndarray:
    """Displacements (6, n, 3) of the unit rigid motions about ``ref``: 3 translations, 3 rotations.

    Rotations are scaled by ``length`` so that all six have displacements of order one.
    """
    d = np.asarray(xyz, float) - np.asarray(ref, float)
    out = np.zeros((6,) + d.shape)
    for k in range(3):
        out[k, :, k] = 1.0
        e = np.zeros(3)
        e[k] = 1.0 / length
        out[3 + k] = np.cross(e, d)
    return out
