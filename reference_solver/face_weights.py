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


def multiplier_shares(face: FaceType, xyz: np.ndarray) -> np.ndarray:
    """int Phi_a dA (nf, k) [m^2] of faces ``xyz`` (nf, k, 3) of type ``face``, Phi the multiplier basis of the
    face-weighted laws: the hat basis on 8-/6-node faces (the row sums of :func:`hat_mortar`; regular quad8:
    corners A/24, mid-sides 5 A/24; tri6: A/12, A/4), Phi = N on 4-/3-node faces (:func:`face_shares`).
    Non-negative, summing to the face's area; summed over a surface's faces they are the rows' contact areas
    (``deckbridge.face_areas.contact_areas`` on quadratic faces, its HRZ areas = these on triangles and
    parallelograms)."""
    if face.n_nodes > face.n_corners:
        return hat_mortar(face, xyz).sum(axis=2)
    return face_shares(face, xyz)


def face_slope(face: FaceType, xyz: np.ndarray, k: np.ndarray, area: np.ndarray) -> np.ndarray:
    """The penalty pressure slope K [Pa/m] of each face ``xyz`` (nf, k, 3) of type ``face``, from the stiffness
    ``k`` [N/m] and the contact area ``area`` [m^2] of its nodes (both (nf, k), the rows' values; area > 0):

        K_f = sum_a s_fa (k_a / A_a) / sum_a s_fa,   s_fa = int_f Phi_a dA  (:func:`multiplier_shares`).

    The one weighting of the face-integrated penalty (``face_penalty.FaceIntegration``) and of the CalculiX
    face-to-face deck's LINEAR slope on quadratic faces (``deckbridge.deck_elements.quadratic_face_slopes``).
    Why these shares: a row's area A_a is the sum over its faces of s_fa (the hat areas of the face-weighted
    laws), so giving each face the part s_fa / A_a of its node's k_a spreads every k_a exactly over its faces,
    and sum_a s_fa = A_f (the Phi sum to 1): sum_f K_f A_f = sum_a k_a, the table's stiffness under a uniform
    penetration d is the model's sum of k whatever k / A does (a block whose faces all get one K penetrates
    p A / sum k under a pressure p). The shares are >= 0, so K_f lies between the face's smallest and largest
    k / A. The consistent shares int N_a dA (quad8 corners -1/12 of A, tri6 corners 0) do neither: they do not
    add up to the hat areas and a large corner k / A can pull K out of that range, even below 0. Where k / A is
    uniform (the model's own penalty: alpha K_bulk / h1) every weighting gives K = k / A. On 4-/3-node faces
    Phi = N: the nodal area shares, as before."""
    s = multiplier_shares(face, xyz)
    q = np.asarray(k, float) / np.asarray(area, float)
    return (s * q).sum(axis=1) / s.sum(axis=1)


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
