"""Face-weighted quantities of a contact surface: the face matrix M, its lumped form, pressure projection.

For a surface made of element faces (any face type of :mod:`element_faces`: quad4, quad8, tri3, tri6),
with face shape functions N_a:

- shares   s_a  = int N_a dA                 [m^2]  (the consistent load of a unit pressure);
- matrix   M_ab = int N_a N_b dA              [m^2]  (consistent, symmetric positive definite);
- lumped   m_a  = sum_b M_ab = s_a            [m^2]  (row sums; on 4-node faces: the tributary areas);
- pressure sigma_N = -M^-1 r                  [Pa]   (L2 projection of nodal forces r [N], r > 0 pressing
  the body onto the surface, so sigma_N < 0 is compression).

Under a uniform pressure p an 8-node face gives its corners -1/12 of p A and its mid-side nodes +1/3; a
6-node face gives its corners 0 and its mid-side nodes 1/3 (``docs/elements.md``). A law with a sign
condition on *nodal* forces (node-to-surface, CGAP) therefore opens the corners of quadratic faces at any
load; a face-weighted law does not.

How a contact law uses these (the law itself lives with the contact laws, not here):
1. Build the surface once: :func:`surface_faces` (faces whose nodes all lie on the surface) then
   :func:`face_matrix` -> ``(surface_nodes, M)`` (sparse, surface-local numbering).
2. Weighted gap: g~ = M g (nodal gaps g [m] -> g~ [m^3]); penalty with slope k_A [Pa/m]: the pressure field
   p = k_A <-g>_+ gives nodal forces r = M p (consistent) or r = m p (lumped; on 4-node faces this is
   today's k_c = k_A x tributary area per node).
3. Lagrange: one multiplier per surface node, the pressure field lambda [Pa]; nodal forces r = M lambda;
   the sign condition is on lambda (or on the weighted gap), never on r.
4. Report sigma_N = :func:`project_pressure` (M, r) (= -lambda for the Lagrange law), node by node.
With ``lumped=True`` every step uses the diagonal m instead of M (a mortar law with a diagonal M). Row-sum
lumping is for 4-node and 3-node faces only: on 8-node faces its corner entries are negative (-1/12 of A)
and on 6-node faces zero, so a diagonal law there needs the consistent M (or a dual basis), never m.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .element_faces import FaceType
from .errors import ReferenceSolverError
from .quadrature import tri_rule


def face_shares(face: FaceType, xyz: np.ndarray) -> np.ndarray:
    """int N_a dA (nf, k) [m^2] of faces ``xyz`` (nf, k, 3) of type ``face``."""
    jw = face.area_jacobian(np.asarray(xyz, float)) * face.weights           # (nf, p)
    return jw @ face.shape(face.points)


def face_mass(face: FaceType, xyz: np.ndarray) -> np.ndarray:
    """int N_a N_b dA (nf, k, k) [m^2] of faces ``xyz`` (nf, k, 3) of type ``face`` (consistent)."""
    jw = face.area_jacobian(np.asarray(xyz, float)) * face.weights
    N = face.shape(face.points)                                              # (p, k)
    return np.einsum("fp,pa,pb->fab", jw, N, N)


def surface_faces(blocks, on_surface: np.ndarray) -> list[tuple[FaceType, np.ndarray]]:
    """Faces of the element ``blocks`` (each with ``element`` and ``cells``) whose nodes all have
    ``on_surface`` (bool per node) true, grouped by face type: [(face type, connectivity (nf, k)), ...].
    ``on_surface`` should mark a boundary surface (an inner face would appear once per element)."""
    on = np.asarray(on_surface, bool)
    out: dict[str, list] = {}
    types: dict[str, FaceType] = {}
    for b in blocks:
        for local, ftype in zip(b.element.faces, b.element.face_types):
            conn = b.cells[:, list(local)]
            hit = on[conn].all(axis=1)
            if hit.any():
                out.setdefault(ftype.name, []).append(conn[hit])
                types[ftype.name] = ftype
    return [(types[k], np.concatenate(v)) for k, v in out.items()]


def multiplier_basis(face: FaceType, alpha: float = 0.2) -> np.ndarray:
    """Q (k, k): a multiplier (pressure) basis Phi_a = sum_b Q_ab N_b with positive shares on 8-/6-node faces
    (Wohlmuth, Popp et al. 2012, modified quadratic basis): a corner takes alpha of each of its two edges'
    mid-side functions, a mid-side keeps 1 - 2 alpha of its own. It sums to 1 and reproduces linear fields
    (mid-sides at edge mid-points); shares with alpha = 1/5: quad8 corners +1/20, mid-sides 1/5 of A; tri6
    2/15 and 1/5. 4- and 3-node faces: Q = I."""
    k, nc = face.n_nodes, face.n_corners
    Q = np.eye(k)
    if k > nc:
        for i in range(nc):                      # mid-side nc + i on the edge (corner i, corner i + 1)
            m = nc + i
            Q[m, m] = 1.0 - 2.0 * alpha
            Q[i, m] = Q[(i + 1) % nc, m] = alpha
    return Q


def _hat_triangles(face: FaceType) -> list[np.ndarray]:
    """Sub-triangles of a quadratic face for :func:`hat_mortar`: each (3, k), the weights of its vertices on
    the face nodes (a node, or the centre of a quad8 = the mean of its mid-sides)."""
    k, nc = face.n_nodes, face.n_corners
    eye = np.eye(k)
    mid = lambda i: eye[nc + i % nc]                       # noqa: E731  mid-side of edge (i, i + 1)
    tris = [np.array([eye[i], mid(i), mid(i - 1)]) for i in range(nc)]          # corner triangles
    if nc == 3:
        tris.append(np.array([mid(0), mid(1), mid(2)]))
    else:
        centre = eye[nc:].mean(axis=0)
        tris += [np.array([mid(i), mid(i + 1), centre]) for i in range(nc)]
    return tris


def hat_mortar(face: FaceType, xyz: np.ndarray) -> np.ndarray:
    """D_ab = int Phi_a N_b dA (nf, k, k) [m^2] with Phi the non-negative hat basis of a quadratic face: piecewise
    linear on the sub-triangles of :func:`_hat_triangles` (corner triangles cut off by the mid-sides; the rest
    a triangle (tri6) or four around the centre (quad8)), Phi_a(node b) = delta_ab, sum 1, linear fields
    reproduced. Non-negative everywhere, so a zero weighted gap int Phi_a g dA = 0 needs the surface to touch
    within Phi_a's support (the modified basis, negative in places, lets g > 0 at every node of a closed row)."""
    xyz = np.asarray(xyz, float)
    tp, tw = tri_rule(4)
    out = np.zeros((xyz.shape[0], face.n_nodes, face.n_nodes))
    for V in _hat_triangles(face):
        corners = V @ face.nodes                                                # (3, 2) natural coordinates
        e1, e2 = corners[1] - corners[0], corners[2] - corners[0]
        det = abs(e1[0] * e2[1] - e1[1] * e2[0])
        pts = corners[0] + tp[:, :1] * e1 + tp[:, 1:] * e2
        bary = np.column_stack([1 - tp.sum(axis=1), tp[:, 0], tp[:, 1]])       # (p, 3)
        phi = bary @ V                                                          # (p, k) hat values
        d = face.dshape(pts)
        a = np.einsum("pa,fad->fpd", d[:, 0], xyz)
        b = np.einsum("pa,fad->fpd", d[:, 1], xyz)
        jw = np.linalg.norm(np.cross(a, b), axis=2) * (tw * det)                # (nf, p)
        out += np.einsum("fp,pa,pb->fab", jw, phi, face.shape(pts))
    return out


def face_matrix(nodes: np.ndarray, faces, lumped: bool = False,
                mortar: bool = False) -> tuple[np.ndarray, sp.csr_matrix]:
    """Surface nodes (m,) and the assembled M (m x m, CSR) [m^2] of ``faces`` [(face type, conn), ...]
    (:func:`surface_faces`); ``lumped``: the diagonal of row sums instead; ``mortar``: the mortar matrix
    D_ab = int Phi_a N_b dA (not symmetric) of the hat basis on 8-/6-node faces (:func:`hat_mortar`; 4-/3-node
    faces keep M)."""
    if not faces:
        raise ReferenceSolverError("contact surface: no element face has all its nodes on it")
    nodes = np.asarray(nodes, float)
    surf = np.unique(np.concatenate([c.ravel() for _, c in faces]))
    rows, cols, vals = [], [], []
    for ftype, conn in faces:
        if mortar and ftype.n_nodes > ftype.n_corners:
            Me = hat_mortar(ftype, nodes[conn])
        else:
            Me = face_mass(ftype, nodes[conn])
        loc = np.searchsorted(surf, conn)
        k = conn.shape[1]
        rows.append(np.repeat(loc, k, axis=1).ravel())
        cols.append(np.tile(loc, (1, k)).ravel())
        vals.append(Me.ravel())
    M = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(surf.size, surf.size))
    if lumped:
        M = sp.diags(np.asarray(M.sum(axis=1)).ravel()).tocsr()
    return surf, M


def project_pressure(M: sp.spmatrix, r: np.ndarray) -> np.ndarray:
    """sigma_N = -M^-1 r [Pa] (< 0 compression) of nodal normal forces ``r`` [N] (> 0 pressing the body
    onto the surface), surface-local order of :func:`face_matrix`: the L2 projection of the pressure."""
    M = sp.csc_matrix(M)
    r = np.asarray(r, float)
    if M.nnz == M.shape[0] and np.all(M.diagonal() > 0) and (abs(M - sp.diags(M.diagonal())).sum() == 0):
        return -r / M.diagonal()
    return -spla.spsolve(M, r)
