"""8-node hexahedra: ``Hex8`` (C3D8, full 2x2x2) and ``Hex8i`` (C3D8I, incompatible modes).

Node order is C3D8 / CHEXA: natural coordinates (xi, eta, zeta) of nodes 1-8 are
(-1,-1,-1) (1,-1,-1) (1,1,-1) (-1,1,-1) (-1,-1,1) (1,-1,1) (1,1,1) (-1,1,1).
Gauss points: the 2 x 2 x 2 rule at +-1/sqrt(3), xi fastest, then eta, then zeta (CalculiX's order).

``Hex8i``: Wilson-Taylor incompatible modes (the C3D8I formulation): 9 extra modes
u_a = (1 - xi_m^2) alpha_{m,c} whose gradients use the Jacobian at the element centre, scaled by
det J0 / det J, so that they integrate to zero and the patch test is passed on any shape. The modes
are condensed per element (exact for linear elasticity); the Gauss-point strains recover them by the
same condensation, alpha = -K_aa^-1 K_au u_e. At the centre their gradient is zero.
Units: coordinates [m], E [Pa] -> stiffness [N/m]; stresses [Pa].
"""

from __future__ import annotations

import numpy as np

from .element_base import Element
from .element_faces import QUAD4
from .kinematics import as_matrix, elasticity_matrix, isotropic_pairs, jacobian, lame, strain_operator

CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                    [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
_G = 1.0 / np.sqrt(3.0)
GAUSS = np.array([[s, t, u] for u in (-_G, _G) for t in (-_G, _G) for s in (-_G, _G)])
# CalculiX faces S1..S6 of C3D8 (0-based local nodes), corners in cyclic order
HEX_FACES = ((0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0))


def shape_gradients(xi: np.ndarray) -> np.ndarray:
    """dN_a/dxi_i of the trilinear hexahedron at natural point ``xi`` (3,): shape (3, 8)."""
    c = CORNERS
    f = 1.0 + c * np.asarray(xi, float)[None, :]     # (8, 3): 1 + xi_i c_ai
    d = np.empty((3, 8))
    d[0] = c[:, 0] * f[:, 1] * f[:, 2]
    d[1] = c[:, 1] * f[:, 0] * f[:, 2]
    d[2] = c[:, 2] * f[:, 0] * f[:, 1]
    return d / 8.0


def shape_values(xi: np.ndarray) -> np.ndarray:
    """Trilinear shape functions N_a (8,) of the corners at natural point ``xi`` (3,)."""
    return np.prod(1.0 + CORNERS * np.asarray(xi, float)[None, :], axis=1) / 8.0


def _pair_matrix(Y: np.ndarray, X: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """``as_matrix(isotropic_pairs(Y, X, lam, mu))`` (ne, 3p, 3q) from one product per element of the Gauss
    sums P[i a, j b] = sum_g Y_iag X_jbg (``Y`` (ne, 3, p, ng), ``X`` (ne, 3, q, ng)); equal to rounding."""
    ne, _, p, ng = Y.shape
    q = X.shape[2]
    P = (Y.reshape(ne, 3 * p, ng) @ X.reshape(ne, 3 * q, ng).swapaxes(1, 2)).reshape(ne, 3, p, 3, q)
    K = lam * P.transpose(0, 2, 1, 4, 3)                                    # [e, a, i, b, j]
    K += mu * P.transpose(0, 2, 3, 4, 1)
    tr = mu * (P[:, 0, :, 0] + P[:, 1, :, 1] + P[:, 2, :, 2])
    for i in range(3):
        K[:, :, i, :, i] += tr
    return K.reshape(ne, 3 * p, 3 * q)


class Hex8(Element):
    """8-node hexahedron, full 2 x 2 x 2 integration (C3D8)."""
    name, aliases, meshio_type = "c3d8", ("hex8",), "hexahedron"
    nodes, points, weights = CORNERS, GAUSS, np.ones(8)
    faces, face_types = HEX_FACES, (QUAD4,) * 6
    opposite_faces = ((0, 1), (2, 4), (3, 5))    # zeta, eta, xi
    recovery = "1 x y z xy yz xz xyz"
    centre = np.zeros(3)

    def shape(self, xi) -> np.ndarray:
        return np.stack([shape_values(x) for x in np.atleast_2d(xi)])

    def dshape(self, xi) -> np.ndarray:
        return np.stack([shape_gradients(x) for x in np.atleast_2d(xi)])

    def extrapolation(self) -> np.ndarray:
        """(8 corners, 8 Gauss points): the inverse of N_a(Gauss_g) (trilinear fit through the 8 values)."""
        return np.linalg.inv(np.stack([shape_values(g) for g in GAUSS]))


class Hex8i(Hex8):
    """8-node hexahedron with incompatible modes (C3D8I), modes condensed per element."""
    name, aliases = "c3d8i", ("hex8i",)

    @staticmethod
    def _mode_gradients(inv0, det0, det, xi) -> np.ndarray:
        """dP_m/dx (ne, 3, 3) of the modes P_m = 1 - xi_m^2 at ``xi``, with J0, scaled by det J0 / det J."""
        return (inv0 @ np.diag(-2.0 * xi)) * (det0 / det)[:, None, None]

    def stiffness_pairs(self, xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
        xyz = np.asarray(xyz, float)
        ne = xyz.shape[0]
        lam, mu = lame(E, nu)
        X = np.empty((ne, 3, 8, 8))
        Y = np.empty((ne, 3, 3, 8))
        _, det0, inv0 = jacobian(xyz, shape_gradients(np.zeros(3)))
        for g, xi in enumerate(GAUSS):
            det, grad = self.point_gradients(xyz, xi)
            root = np.sqrt(det)[:, None, None]                   # Gauss weight 1
            X[..., g] = grad * root
            Y[..., g] = self._mode_gradients(inv0, det0, det, xi) * root
        K = isotropic_pairs(X, X, lam, mu)
        Kua = as_matrix(isotropic_pairs(X, Y, lam, mu))                          # (ne, 24, 9)
        Kaa = as_matrix(isotropic_pairs(Y, Y, lam, mu))                          # (ne, 9, 9)
        C = Kua @ np.linalg.solve(Kaa, np.swapaxes(Kua, 1, 2))                   # (ne, 24, 24)
        K -= C.reshape(ne, 8, 3, 8, 3).transpose(0, 2, 4, 1, 3)
        K = np.add(K, K.transpose(0, 2, 1, 4, 3))                 # symmetric part (no overlap copy)
        K *= 0.5
        return K

    def gauss_strain_operator(self, xyz: np.ndarray, E: float, nu: float) -> np.ndarray:
        """B_u + B_a A (ne, 8, 6, 24): the modes' amplitudes alpha = A u_e folded in (depends on E, nu).
        Element-major arrays, the 8 Gauss points stacked as 48 rows, batched matmul (the first version's
        einsum(optimize=True) took 2.7x as long)."""
        xyz = np.asarray(xyz, float)
        ne = xyz.shape[0]
        Bu, Ba, dets = np.empty((ne, 8, 6, 24)), np.empty((ne, 8, 6, 9)), np.empty((ne, 8, 1, 1))
        _, det0, inv0 = jacobian(xyz, shape_gradients(np.zeros(3)))
        for g, xi in enumerate(GAUSS):
            det, grad = self.point_gradients(xyz, xi)
            Bu[:, g], dets[:, g, 0, 0] = strain_operator(grad), det
            Ba[:, g] = strain_operator(self._mode_gradients(inv0, det0, det, xi))
        DBaW = ((elasticity_matrix(E, nu) @ Ba) * dets).reshape(ne, 48, 9).transpose(0, 2, 1)   # Gauss weights 1
        Bu48, Ba48 = Bu.reshape(ne, 48, 24), Ba.reshape(ne, 48, 9)
        A = -np.linalg.solve(DBaW @ Ba48, DBaW @ Bu48)        # K_aa^-1 K_au (ne, 9, 24): alpha = A u_e
        Bu48 += Ba48 @ A
        return Bu

    def displacement_gradients(self, xyz: np.ndarray, ue: np.ndarray, E: float, nu: float):
        """du/dx (ne, 8, 3, 3, m) of m states and w det J (ne, 8), the modes recovered from the states
        themselves: alpha = -K_aa^-1 (K_au u_e) with K_au and K_aa built as in :meth:`stiffness_pairs`, then
        du/dx = grad N u_e + G alpha, G (3, 3 modes) the modes' gradients, in one product per Gauss point.
        Equal to :meth:`gauss_strain_operator` @ u_e to rounding, without the (ne, 8, 6, 24) operator."""
        xyz = np.asarray(xyz, float)
        ne, _, _, m = ue.shape
        lam, mu = lame(E, nu)
        det, grad = self.gauss_gradients(xyz)                               # (ne, 8), (ne, 8, 3, 8)
        _, det0, inv0 = jacobian(xyz, shape_gradients(np.zeros(3)))
        B = np.empty((ne, 8, 3, 11))                                        # [grad N | -G] per Gauss point
        B[..., :8] = grad
        G = B[..., 8:]                                                      # the modes' gradients [i, mode]
        np.multiply(inv0[:, None], (-2.0 * GAUSS)[None, :, None, :], out=G)
        G *= (det0[:, None] / det)[:, :, None, None]
        root = np.sqrt(det)[:, None, None, :]                               # Gauss weights 1
        Y = G.transpose(0, 2, 3, 1) * root                                  # (ne, 3, 3 modes, 8 points)
        Kau = _pair_matrix(Y, grad.transpose(0, 2, 3, 1) * root, lam, mu)   # (ne, 9, 24)
        Kaa = _pair_matrix(Y, Y, lam, mu)                                   # (ne, 9, 9)
        x = np.empty((ne, 11, 3 * m))                                       # [u_e; -alpha]
        x[:, :8] = ue.reshape(ne, 8, 3 * m)
        x[:, 8:] = np.linalg.solve(Kaa, Kau @ ue.reshape(ne, 24, m)).reshape(ne, 3, 3 * m)
        G *= -1.0
        H = B.reshape(ne, 24, 11) @ x                                       # (ne, 8 x 3, 3m): du_c/dx_i
        return H.reshape(ne, 8, 3, 3, m), det
