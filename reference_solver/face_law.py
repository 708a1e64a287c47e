"""The face-weighted (mortar-type) Lagrange law: contact through the surface's mortar matrix, not node by node.

Nodal laws put the sign condition on nodal forces r [N]; on 8-node faces a uniform pressure gives the corners
-1/12 of p A (6-node faces: 0), so they open every corner at zero load (``docs/elements.md``). Here the unknown
on each surface is a pressure field p = sum_b lambda_b Phi_b [Pa] (lambda > 0 compressive) in a non-negative
multiplier basis: the hat basis of :func:`reference_solver.face_weights.hat_mortar` (the earlier modified
basis Phi = Q N of Wohlmuth / Popp et al., since removed, had positive shares but was negative in parts of
the face, so rows could close while the surface around them was open), with

    D_ab = int Phi_a N_b dA [m^2],   nodal forces r = D^T lambda,   weighted gaps g~ = D g [m^3]

(g = clearance + u, > 0 open; 'face-lumped': D = the row sums of M, for 4- and 3-node faces only, where it is a
diagonal scaling of the nodal law). Rows on no face of their surface (a line of nodes: the stop) keep
D = their ``contact_area``. D is invertible, so the condensed LCP w = S g + q >= 0 (w = r) becomes

    lambda = S~ g~ + q~ >= 0,  g~ >= 0,  lambda . g~ = 0,   S~ = D^-T S D^-1 (SPD),  q~ = D^-T q,

solved by the nodal law's own LCP algorithms. sigma_N = -lambda: with the hat basis a node's pressure is its
own multiplier. With Phi = N (D = M, symmetric) a uniform lift would give g~ < 0 at 8-node
corners: the base could not lift. Chosen by ``Problem.contact_weighting`` ('nodal' default | 'face' |
'face-lumped' | 'face-dual'); frictionless Lagrange here (penalty: :mod:`reference_solver.face_penalty`; friction,
every method: the same change of variables in :mod:`reference_solver.friction_face`; :func:`reference_solver.laws.make_law`
refuses the rest in one line).

'face-dual' takes CalculiX 2.20's ``TYPE=MORTAR`` multiplier basis instead of the hat one (Sitzmann's quadratic
dual mortar, :func:`reference_solver.face_weights.dual_mortar`): dual functions psi biorthogonal to the transformed
slave functions Nt = T N (alpha = 1/5), D = diag(d) T^-T with d = int Nt dA, so lambda_j >= 0 and the weighted gap
>= 0 hold node by node in ccx's own variables and sigma_N = -lambda is the multiplier ccx's forces give
(lambda = T r / d). The pressure field sum lambda_j psi_j is not >= 0 pointwise (a dual function is negative in
part of its face); it is the partner of ccx's mortar deck, the hat basis stays the default (docs/elements.md).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .face_weights import face_matrix, surface_faces

WEIGHTINGS = ("nodal", "face", "face-lumped", "face-dual")


def weighting_matrix(p) -> sp.csc_matrix:
    """D (nc x nc) [m^2] of a problem's contact rows: the mortar matrix int Phi_a N_b dA of each contact surface
    (:func:`reference_solver.face_weights.face_matrix` with ``mortar``: the hat basis; 'face-dual': CalculiX's dual
    basis; 'face-lumped': the row sums of M) on the rows of that surface whose nodes lie on one of its faces,
    ``contact_area`` on the diagonal of every other."""
    nc = p.n_contacts
    lumped = p.contact_weighting == "face-lumped"
    rows, cols, vals = [], [], []
    covered = np.zeros(nc, bool)
    for label in np.unique(p.contact_surface):
        idx = np.flatnonzero(p.contact_surface == label)
        on = np.zeros(p.n_nodes, bool)
        on[p.contact_nodes[idx]] = True
        faces = surface_faces(p.blocks, on)
        if not faces:
            continue
        surf, M = face_matrix(p.nodes, faces, lumped=lumped, mortar=not lumped,
                              basis="dual" if p.contact_weighting == "face-dual" else "hat")
        row_of = np.full(p.n_nodes, -1)
        row_of[p.contact_nodes[idx]] = idx
        r = row_of[surf]                                  # every surf node is a row of this surface
        M = M.tocoo()
        rows.append(r[M.row]), cols.append(r[M.col]), vals.append(M.data)
        covered[r] = True
    rest = np.flatnonzero(~covered)
    rows.append(rest), cols.append(rest), vals.append(p.contact_area[rest])
    return sp.csc_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(nc, nc))


class FaceWeighting:
    """The transformation of one condensed system by D = :func:`weighting_matrix`: S~ = D^-T S D^-1 and the maps
    between (g~, lambda) and (g, r): g~ = D g, r = D^T lambda."""

    def __init__(self, problem, Sc: np.ndarray):
        self.D = weighting_matrix(problem)
        self._lu = spla.splu(self.D)
        Y = self.to_pressure(np.asarray(Sc))              # D^-T S
        St = self.to_pressure(Y.T).T                       # (D^-T S^T D^-1)^T = D^-T S D^-1 (S symmetric)
        self.S = 0.5 * (St + St.T)

    def to_pressure(self, r: np.ndarray) -> np.ndarray:
        """D^-T r: pressures [Pa] from nodal forces [N] (r a vector or a matrix of columns)."""
        return self._lu.solve(np.asarray(r, float), trans="T")

    def to_gap(self, gw: np.ndarray) -> np.ndarray:
        """D^-1 g~: nodal gaps [m] from weighted gaps [m^3]."""
        return self._lu.solve(np.asarray(gw, float))

    def weigh(self, g: np.ndarray) -> np.ndarray:
        """D g: weighted gaps [m^3] from nodal gaps [m]."""
        return self.D @ g

    def to_force(self, lam: np.ndarray) -> np.ndarray:
        """D^T lambda: nodal forces [N] from pressures [Pa]."""
        return self.D.T @ lam
