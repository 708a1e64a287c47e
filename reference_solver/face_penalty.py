"""The face-integrated penalty law: the gap evaluated at integration points of the contact faces (issues 23, 24).

The nodal :class:`reference_solver.laws.PenaltyLaw` puts a bilinear spring k_c,i on each contact row. This law
integrates a pressure over the faces of each contact surface instead (the penalty of CalculiX's face-to-face
contact, ``*CONTACT PAIR, TYPE=SURFACE TO SURFACE`` with ``PRESSURE-OVERCLOSURE=LINEAR``):

    g(x) = sum_a N_a(x) g_a  [m]  (g_a = clearance + u of row a, > 0 open; N_a the face shape functions),
    p(x) = K_eff(g) (-g(x))  [Pa] (> 0 compressive), K_eff = K closed (g <= 0), k_open_ratio x K open,
    r_a  = int N_a p dA      [N]  (nodal forces, > 0 compressive),
    tangent sum over the points of K_eff w N N^T  [N/m],

summed over the integration points of every face whose nodes are all rows of one surface (any face type of
:mod:`reference_solver.element_faces`: quad4, quad8, tri3, tri6). Rows on no face of their surface (a line of
nodes: the radial stop) keep the nodal bilinear spring k_c of PenaltyLaw. The energy
1/2 u'Su - f'u + 1/2 sum_points w K_eff g^2 is convex and piecewise quadratic: Newton on the active set of
the *points* (a state that repeats is damped by an Armijo line search, as :func:`contact.penalty_solve`).

Slope of a face [Pa/m]: :func:`face_weights.face_slope`, the one weighting the ccx deck uses too
(``docs/ccx_f2f.md``): K = sum_a s_a (k_c,a / A_a) / sum_a s_a with s_a = int Phi_a dA (Phi = N on 4-/3-node
faces: the nodal area shares; the hat multiplier basis on 8-/6-node faces, whose sums are the rows' areas) and
A_a = ``contact_area``: sum over the faces of K x area = sum of k_c (any k), and a uniform penetration d gives
each node of a 4-node face exactly k_c,a d when k_c / A is uniform, the model's rule.

Quadrature (chosen to be CalculiX's on a master that matches the slave node for node, as the deck's table).
What ccx 2.20 does (slavintpoints.f, treatmasterface.f, read, not copied): the slave face is projected on
its mean plane and cut (Sutherland-Hodgman) with each master face it overlaps; an 8-node master face is
first split into its 4 corner triangles (corner, mid, mid) and the inner quadrilateral of its mid-side
nodes, a 6-node one into 4 triangles; a cut polygon of 3 vertices is one triangle, a larger one is split
into triangles from its vertex centroid; each triangle gets the 7-point degree-5 rule (Radon) in the
slave's natural coordinates, weight 2 x (its natural area) x w_i, times the slave face's area Jacobian.
What this law does: the same triangles for a matching master (quad4: 4 triangles from the face centre;
quad8: 4 corner triangles + the inner quadrilateral in 4 from the centre; tri3: 1; tri6: 4) with the same
7-point rule: 28 / 56 / 7 / 28 points a face. On a face where the gap keeps one sign the integral is exact
(degree <= 5); across the contact edge both codes integrate the kink of max(0, -g) the same way.

Status: a row on a face is closed while an integration point in its support is active (its face pressure
reaches it: the node carries compression, as ccx's f2f status by force, and the face-weighted Lagrange law's
by weighted gap), so a node at the contact edge with a small positive gap can be closed; rows off the faces
by their gap. The driver's liftoff onset is the first row that opens in this sense.
sigma_N [Pa] (< 0 compression): -r_a / contact_area on 4-/3-node faces (the ccx deck's -F / A); on a problem
with 8-/6-node faces and ``contact_weighting='face'``, the pressure field of the face-weighted law's
projection -E D^-T r (:mod:`reference_solver.face_law`), exact (-p) for a uniform pressure p.
Chosen by ``method='penalty'`` with ``contact_weighting='face'`` (:data:`reference_solver.laws.WEIGHTED_LAWS`
read by :func:`reference_solver.laws.make_law`; :func:`face_weighted` gives a condensed system that weighting
without condensing again). Frictionless; onsets are bisected by the driver (``track`` None).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from .contact import Unbounded
from .errors import ReferenceSolverError
from .face_weights import face_slope, surface_faces
from .laws import WEIGHTED_LAWS, ContactLaw

_A1, _A2 = (6 - np.sqrt(15)) / 21, (6 + np.sqrt(15)) / 21
_W1, _W2 = (155 - np.sqrt(15)) / 1200, (155 + np.sqrt(15)) / 1200
RADON7 = (np.array([[1 / 3, 1 / 3], [_A1, _A1], [1 - 2 * _A1, _A1], [_A1, 1 - 2 * _A1],
                    [_A2, _A2], [1 - 2 * _A2, _A2], [_A2, 1 - 2 * _A2]]),
          np.array([9 / 40, _W1, _W1, _W1, _W2, _W2, _W2]))      # barycentric (s, t), weights sum to 1

_C, _Q = [(-1, -1), (1, -1), (1, 1), (-1, 1)], [(0, -1), (1, 0), (0, 1), (-1, 0)]
_T = [(0, 0), (1, 0), (0, 1)]
_TM = [(0.5, 0), (0.5, 0.5), (0, 0.5)]
_fan = lambda poly: [((0.0, 0.0), poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly))]  # noqa: E731
SUBTRIANGLES = {                                   # natural-coordinate triangles of a face against its twin master
    "quad4": _fan(_C),
    "quad8": [(_C[i], _Q[i], _Q[i - 1]) for i in range(4)] + _fan(_Q),
    "tri3": [tuple(_T)],
    "tri6": [(_T[0], _TM[0], _TM[2]), (_TM[0], _T[1], _TM[1]), (_TM[1], _T[2], _TM[2]), tuple(_TM)],
}


def face_points(face_name: str) -> tuple[np.ndarray, np.ndarray]:
    """Integration points (p, 2) and weights (p,) in the natural coordinates of a face type (weights sum to
    the reference area: 4 on quadrilaterals, 1/2 on triangles): the 7-point rule on each of its
    :data:`SUBTRIANGLES`."""
    pts, wts = [], []
    bary, w = RADON7
    for a, b, c in SUBTRIANGLES[face_name]:
        a, b, c = (np.asarray(v, float) for v in (a, b, c))
        area = 0.5 * abs((b - a)[0] * (c - a)[1] - (b - a)[1] * (c - a)[0])
        pts.append(a + np.outer(bary[:, 0], b - a) + np.outer(bary[:, 1], c - a))
        wts.append(area * w)
    return np.vstack(pts), np.concatenate(wts)


class FaceIntegration:
    """The integration points of a problem's contact faces: G (npts x nc) interpolates the row gaps to the
    points, ``w`` (npts,) = K |J| w_nat [N/m] (the point's slope times its area), ``xyz`` (npts, 3) [m] their
    places on the undeformed faces, ``on_face`` marks the rows on a face (the others keep nodal springs)."""

    def __init__(self, p):
        nc = p.n_contacts
        rows, cols, vals, weights, places = [], [], [], [], []
        self.on_face = np.zeros(nc, bool)
        self.quadratic = False
        npts = 0
        for label in np.unique(p.contact_surface):
            idx = np.flatnonzero(p.contact_surface == label)
            on = np.zeros(p.n_nodes, bool)
            on[p.contact_nodes[idx]] = True
            row_of = np.full(p.n_nodes, -1)
            row_of[p.contact_nodes[idx]] = idx
            for ftype, conn in surface_faces(p.blocks, on):
                xyz = p.nodes[conn]
                r = row_of[conn]                                            # (nf, k) contact rows
                K = face_slope(ftype, xyz, p.contact_k[r], p.contact_area[r])  # [Pa/m] per face
                st, wn = face_points(ftype.name)
                N = ftype.shape(st)                                         # (g, k)
                d = ftype.dshape(st)
                ta = np.einsum("pa,fad->fpd", d[:, 0], xyz)
                tb = np.einsum("pa,fad->fpd", d[:, 1], xyz)
                J = np.linalg.norm(np.cross(ta, tb), axis=2)                # (nf, g) area Jacobian
                nf, ng, k = r.shape[0], st.shape[0], r.shape[1]
                pid = npts + np.arange(nf * ng).reshape(nf, ng)
                rows.append(np.repeat(pid[:, :, None], k, axis=2).ravel())
                cols.append(np.broadcast_to(r[:, None, :], (nf, ng, k)).ravel())
                vals.append(np.broadcast_to(N[None], (nf, ng, k)).ravel())
                weights.append((K[:, None] * J * wn[None]).ravel())
                places.append(np.einsum("pa,fad->fpd", N, xyz).reshape(-1, 3))
                npts += nf * ng
                self.on_face[r.ravel()] = True
                self.quadratic |= ftype.n_nodes > ftype.n_corners
        self.G = sp.csr_matrix((np.concatenate(vals) if vals else np.zeros(0),
                                (np.concatenate(rows) if rows else np.zeros(0, int),
                                 np.concatenate(cols) if cols else np.zeros(0, int))), shape=(npts, nc))
        self.w = np.concatenate(weights) if weights else np.zeros(0)
        self.xyz = np.concatenate(places) if places else np.zeros((0, 3))

    def nodal_k(self) -> np.ndarray:
        """The stiffness of each row under a uniform penetration, sum over points of N_a w [N/m] (k_c,a on
        4-node faces whose k_c / A is uniform; 0 off the faces)."""
        return self.G.T @ self.w


class FacePenaltyLaw(ContactLaw):
    """Penalty integrated over the contact faces (module doc); forces r = int N p dA [N] per row. The method
    is 'penalty' (``contact_weighting='face'`` picks this law in :func:`reference_solver.laws.make_law`)."""
    name, algorithms, uses_k, tips_open = "penalty", ("newton",), True, True

    def __init__(self, system, k_factor=1.0, algorithm=None):
        super().__init__(system, k_factor, algorithm)
        p = self.problem
        self.fi = FaceIntegration(p)
        self.w = self.k_factor * self.fi.w                                   # [N/m] per point
        self.kn = np.where(self.fi.on_face, 0.0, self.k_factor * p.contact_k)  # nodal springs off the faces
        self.ratio = p.k_open_ratio
        self.G, self.GT = self.fi.G, self.fi.G.T.tocsr()
        self._field = None
        if self.fi.quadratic and p.contact_weighting == "face":
            from .face_law import weighting_matrix
            import scipy.sparse.linalg as spla
            self._field = spla.splu(weighting_matrix(p).tocsc())

    @property
    def penalty_k(self):
        return self.fi.nodal_k() * self.k_factor + self.kn

    def _stiff(self, g_pts, g):
        return (np.where(g_pts <= 0, self.w, self.ratio * self.w), np.where(g <= 0, self.kn, self.ratio * self.kn))

    def _energy(self, u, f):
        g = self.c0 + u
        gp = self.G @ g
        e, en = self._stiff(gp, g)
        return 0.5 * u @ (self.system.Sc @ u) - f @ u + 0.5 * (e @ (gp * gp) + en @ (g * g))

    def increment(self, prev, coeffs, guess=None, depth=0):
        S, f = self.system.Sc, self.load(coeffs)
        warm = self.warm(prev)
        u = np.zeros(f.size) if warm is None else np.array(warm, float)
        seen = set()
        for it in range(1, 201):
            g = self.c0 + u
            gp = self.G @ g
            e, en = self._stiff(gp, g)
            key = (gp <= 0).tobytes() + (g <= 0).tobytes()
            H = S + (self.GT @ sp.diags(e) @ self.G).toarray() + np.diag(en)
            rhs = f - self.GT @ (e * (self.G @ self.c0)) - en * self.c0
            try:
                u_new = sla.cho_solve(sla.cho_factor(H), rhs)
            except np.linalg.LinAlgError:
                raise ReferenceSolverError("face penalty: S + K_contact is not positive definite") from None
            g_new = self.c0 + u_new
            if (((self.G @ g_new) <= 0).tobytes() + (g_new <= 0).tobytes()) == key:
                u = u_new
                break
            d = u_new - u
            if key in seen:                                                   # cycling: damp the step
                e0 = self._energy(u, f)
                slope = (S @ u - f + self.GT @ (e * gp) + en * g) @ d
                t = 1.0
                while t > 1e-10 and self._energy(u + t * d, f) > e0 + 1e-4 * t * slope:
                    t *= 0.5
                u = u + (t if t > 1e-10 else 1.0) * d
            else:
                u = u_new
            seen.add(key)
        else:
            raise ReferenceSolverError("face penalty: the active integration points did not settle in 200 "
                                       "iterations")
        if not np.all(np.isfinite(u)) or np.abs(u).max() > self.max_disp:
            raise Unbounded("penalty displacements beyond the sane limit")
        g = self.c0 + u
        gp = self.G @ g
        e, en = self._stiff(gp, g)
        force = -(self.GT @ (e * gp)) - en * g
        pressed = (abs(self.GT) @ (gp <= 0).astype(float)) > 0             # an active point in the node's support
        return self.checked(u, force, np.where(self.fi.on_face, pressed, g <= 0), it)

    def sigma_n(self, force):
        """-r / contact_area [Pa]; with 8-/6-node faces and 'face' weighting the projected field -D^-T r (hat basis:
        a node's pressure is its own multiplier, face_law.py)."""
        if self._field is None:
            return super().sigma_n(force)
        return 0.0 - self._field.solve(np.asarray(force, float).T, trans="T").T


WEIGHTED_LAWS["face", "penalty"] = FacePenaltyLaw


def face_weighted(system):
    """A shallow copy of a condensed system whose problem has ``contact_weighting='face'`` (same matrices): its
    'penalty' is this law, its 'lagrange' the face-weighted Lagrange law."""
    import dataclasses
    return dataclasses.replace(system, problem=dataclasses.replace(system.problem, contact_weighting="face"))
