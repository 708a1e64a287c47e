"""The face-weighted (mortar-type) Lagrange law: contact through the surface's face matrix M, not node by node.

Nodal laws put the sign condition on nodal forces r [N]; on 8-node faces a uniform pressure gives the
corners -1/12 of p A (6-node faces: 0), so they open every corner at zero load (``docs/elements.md``). Here the
unknown on each surface is a pressure field lambda [Pa] (> 0 compressive) with nodal forces r = T lambda and the
weighted gaps g~ = T g [m^3] (g = clearance + u, > 0 open), T = M = int N_a N_b dA per contact surface
(:mod:`reference_solver.face_weights`; ``face-lumped``: its row sums, for 4- and 3-node faces only). Rows on no
face of their surface (a line of nodes: the stop) keep T = their ``contact_area`` (a nodal row in pressure units).
T is symmetric positive definite, so the condensed LCP w = S g + q >= 0 (w = r) becomes, in g~,

    lambda = S~ g~ + q~ >= 0,  g~ >= 0,  lambda . g~ = 0,   S~ = T^-1 S T^-1,  q~ = T^-1 q,

solved by the nodal law's own LCP algorithms. sigma_N = -lambda is the L2-projected pressure (-M^-1 r). With
``face-lumped`` on 4-node faces T = diag(tributary areas): a diagonal scaling of the nodal LCP, same solution.
Chosen by ``Problem.contact_weighting`` ('nodal' default | 'face' | 'face-lumped'); Lagrange only, frictionless
(:func:`reference_solver.laws.make_law` refuses the rest in one line).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .face_weights import face_matrix, surface_faces

WEIGHTINGS = ("nodal", "face", "face-lumped")


def weighting_matrix(p) -> sp.csc_matrix:
    """T (nc x nc) [m^2] of a problem's contact rows: the face matrix M of each contact surface on the rows of
    that surface whose nodes lie on one of its faces, ``contact_area`` on the diagonal of every other row."""
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
        surf, M = face_matrix(p.nodes, faces, lumped=lumped)
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
    """The transformation of one condensed system: S~ and the maps between (g~, lambda) and (g, r)."""

    def __init__(self, problem, Sc: np.ndarray):
        self.T = weighting_matrix(problem)
        self._lu = spla.splu(self.T)
        X = self.solve(np.asarray(Sc))                    # T^-1 S
        St = self.solve(X.T)                              # T^-1 S^T T^-1 = S~ (S symmetric)
        self.S = 0.5 * (St + St.T)

    def solve(self, b: np.ndarray) -> np.ndarray:
        """T^-1 b (b a vector or a matrix of columns)."""
        return self._lu.solve(np.asarray(b, float))

    def apply(self, x: np.ndarray) -> np.ndarray:
        """T x (weighted gaps from gaps, nodal forces [N] from pressures [Pa])."""
        return self.T @ x
