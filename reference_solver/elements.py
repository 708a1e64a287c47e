"""8-node hexahedra for small-strain isotropic elasticity, vectorised over elements.

Node order is C3D8 / CHEXA: natural coordinates (xi, eta, zeta) of nodes 1-8 are
(-1,-1,-1) (1,-1,-1) (1,1,-1) (-1,1,-1) (-1,-1,1) (1,-1,1) (1,1,1) (-1,1,1).
Element dofs are ordered (u_x, u_y, u_z) per node, node by node (24 per element).

``c3d8i``: Wilson-Taylor incompatible modes (the C3D8I formulation): 9 extra modes
u_a = (1 - xi_m^2) alpha_{m,c} whose gradients use the Jacobian at the element centre, scaled by
det J0 / det J, so that they integrate to zero and the patch test is passed on any shape. The modes
are condensed per element (exact for linear elasticity). ``c3d8``: plain full 2x2x2 integration.
Units: coordinates [m], E [Pa] -> stiffness [N/m]; stresses [Pa].
"""

from __future__ import annotations

import numpy as np

ELEMENTS = ("c3d8i", "c3d8")

_CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
_G = 1.0 / np.sqrt(3.0)
_GAUSS = np.array([[s, t, u] for u in (-_G, _G) for t in (-_G, _G) for s in (-_G, _G)])


def shape_gradients(xi: np.ndarray) -> np.ndarray:
    """dN_a/dxi_i at natural point ``xi`` (3,): shape (3, 8)."""
    c = _CORNERS
    f = 1.0 + c * xi[None, :]                  # (8, 3): 1 + xi_i c_ai
    d = np.empty((3, 8))
    d[0] = c[:, 0] * f[:, 1] * f[:, 2]
    d[1] = c[:, 1] * f[:, 0] * f[:, 2]
    d[2] = c[:, 2] * f[:, 0] * f[:, 1]
    return d / 8.0


def elasticity_matrix(E: float, nu: float) -> np.ndarray:
    """Isotropic 6x6 matrix, Voigt order (xx, yy, zz, xy, yz, zx), engineering shear strains."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    return D


def strain_operator(grad: np.ndarray) -> np.ndarray:
    """B matrices from spatial gradients ``grad`` (ne, 3, k) of k vector fields: (ne, 6, 3k)."""
    ne, _, k = grad.shape
    B = np.zeros((ne, 6, 3 * k))
    gx, gy, gz = grad[:, 0], grad[:, 1], grad[:, 2]
    B[:, 0, 0::3] = gx
    B[:, 1, 1::3] = gy
    B[:, 2, 2::3] = gz
    B[:, 3, 0::3] = gy
    B[:, 3, 1::3] = gx
    B[:, 4, 1::3] = gz
    B[:, 4, 2::3] = gy
    B[:, 5, 0::3] = gz
    B[:, 5, 2::3] = gx
    return B


def _jacobian(xyz: np.ndarray, dnat: np.ndarray):
    """J_ij = dx_j/dxi_i (ne, 3, 3), its determinant and inverse (closed-form 3x3 adjugate)."""
    J = np.einsum("ia,eaj->eij", dnat, xyz)
    a, b, c = J[:, 0, 0], J[:, 0, 1], J[:, 0, 2]
    d, e, f = J[:, 1, 0], J[:, 1, 1], J[:, 1, 2]
    g, h, k = J[:, 2, 0], J[:, 2, 1], J[:, 2, 2]
    adj = np.empty_like(J)
    adj[:, 0, 0], adj[:, 0, 1], adj[:, 0, 2] = e * k - f * h, c * h - b * k, b * f - c * e
    adj[:, 1, 0], adj[:, 1, 1], adj[:, 1, 2] = f * g - d * k, a * k - c * g, c * d - a * f
    adj[:, 2, 0], adj[:, 2, 1], adj[:, 2, 2] = d * h - e * g, b * g - a * h, a * e - b * d
    det = a * adj[:, 0, 0] + b * adj[:, 1, 0] + c * adj[:, 2, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = adj / det[:, None, None]
    return J, det, inv


def _lame(E: float, nu: float) -> tuple[float, float]:
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


def _isotropic_pairs(X: np.ndarray, Y: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """Stiffness coupling of two sets of gradient fields, Lame form, by component pairs.

    ``X`` (ne, 3, p, ng) and ``Y`` (ne, 3, q, ng): spatial gradients d/dx_i of p (q) scalar shape
    functions at the Gauss points, already scaled by sqrt(w det J). Returns (ne, 3, 3, p, q):
    [e, i, j, a, b] = K[a i, b j] = sum_g lam X_ia Y_jb + mu X_ja Y_ib + mu delta_ij X_ka Y_kb
    (component-major: each 3x3 component is one contiguous p x q block per element).
    """
    M = np.matmul(X[:, :, None], np.swapaxes(Y, 2, 3)[:, None])            # [e, i, j, a, b] = X_ia . Y_jb
    K = np.multiply(M, lam)
    K += np.multiply(np.swapaxes(M, 1, 2), mu)
    tr = M[:, 0, 0] + M[:, 1, 1] + M[:, 2, 2]
    tr *= mu
    for i in range(3):
        K[:, i, i] += tr
    return K


def _as_matrix(K: np.ndarray) -> np.ndarray:
    """(ne, 3, 3, p, q) component pairs -> (ne, 3p, 3q) with dofs (field, component)."""
    ne, _, _, p, q = K.shape
    return K.transpose(0, 3, 1, 4, 2).reshape(ne, 3 * p, 3 * q)


def hex8_stiffness_pairs(xyz: np.ndarray, E: float, nu: float, element: str = "c3d8i") -> np.ndarray:
    """Element stiffness of hexahedra ``xyz`` (ne, 8, 3) as node-pair blocks (ne, 3, 3, 8, 8) [N/m]:
    [e, i, j, a, b] couples component i of node a to component j of node b (symmetric)."""
    if element not in ELEMENTS:
        raise ValueError(f"element = {element!r}: must be one of {', '.join(ELEMENTS)}")
    xyz = np.asarray(xyz, float)
    ne = xyz.shape[0]
    lam, mu = _lame(E, nu)
    inc = element == "c3d8i"
    X = np.empty((ne, 3, 8, len(_GAUSS)))
    Y = np.empty((ne, 3, 3, len(_GAUSS)))
    if inc:
        _, det0, inv0 = _jacobian(xyz, shape_gradients(np.zeros(3)))
    for g, xi in enumerate(_GAUSS):
        _, det, inv = _jacobian(xyz, shape_gradients(xi))
        if np.any(det <= 0):
            bad = int(np.flatnonzero(det <= 0)[0])
            raise ValueError(f"element {bad}: non-positive Jacobian (inverted or degenerate hexahedron)")
        root = np.sqrt(det)[:, None, None]                     # Gauss weight 1
        X[..., g] = (inv @ shape_gradients(xi)) * root         # dN/dx
        if inc:                                                # dP_m/dx with J0, modes P_m = 1 - xi_m^2
            Y[..., g] = (inv0 @ np.diag(-2.0 * xi)) * (det0 / det)[:, None, None] * root
    K = _isotropic_pairs(X, X, lam, mu)
    if inc:                                                    # condense the modes: K -= Kua Kaa^-1 Kau
        Kua = _as_matrix(_isotropic_pairs(X, Y, lam, mu))                      # (ne, 24, 9)
        Kaa = _as_matrix(_isotropic_pairs(Y, Y, lam, mu))                      # (ne, 9, 9)
        C = Kua @ np.linalg.solve(Kaa, np.swapaxes(Kua, 1, 2))                 # (ne, 24, 24)
        K -= C.reshape(ne, 8, 3, 8, 3).transpose(0, 2, 4, 1, 3)
    K = np.add(K, K.transpose(0, 2, 1, 4, 3))                   # symmetric part (no overlap copy)
    K *= 0.5
    return K


def hex8_stiffness(xyz: np.ndarray, E: float, nu: float, element: str = "c3d8i") -> np.ndarray:
    """Element stiffness matrices (ne, 24, 24) of hexahedra with corner coordinates ``xyz`` (ne, 8, 3)."""
    return _as_matrix(hex8_stiffness_pairs(xyz, E, nu, element))


def centroid_strain(xyz: np.ndarray, ue: np.ndarray) -> np.ndarray:
    """Strain (ne, 6) at element centres from element displacements ``ue`` (ne, 24).

    At the centre the incompatible modes have zero gradient, so this holds for c3d8i as well.
    """
    _, _, inv = _jacobian(np.asarray(xyz, float), shape_gradients(np.zeros(3)))
    B = strain_operator(inv @ shape_gradients(np.zeros(3)))
    return np.einsum("eij,ej->ei", B, ue)


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of Voigt stresses (..., 6) [Pa]."""
    sx, sy, sz, txy, tyz, tzx = np.moveaxis(stress, -1, 0)
    return np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2)
                   + 3.0 * (txy ** 2 + tyz ** 2 + tzx ** 2))
