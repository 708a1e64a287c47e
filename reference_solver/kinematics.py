"""Small-strain kinematics shared by every element type, vectorised over elements.

Voigt order of every strain and stress array: (xx, yy, zz, xy, yz, zx), engineering shear strains.
Jacobian convention: J_ij = dx_j / dxi_i (natural coordinates xi, physical x). Units: coordinates
[m], E [Pa] -> stiffness [N/m]; stresses [Pa], tension > 0.
"""

from __future__ import annotations

import numpy as np


def elasticity_matrix(E: float, nu: float) -> np.ndarray:
    """Isotropic 6x6 matrix, Voigt order (xx, yy, zz, xy, yz, zx), engineering shear strains."""
    lam = E * nu / ((1 + nu) * (1 - 2 * nu))
    mu = E / (2 * (1 + nu))
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(3), np.arange(3)] += 2 * mu
    D[np.arange(3, 6), np.arange(3, 6)] = mu
    return D


def lame(E: float, nu: float) -> tuple[float, float]:
    """Lame constants (lambda, mu) [Pa]."""
    return E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))


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


def gradient_to_strain() -> np.ndarray:
    """(6, 9): engineering strains (Voigt xx, yy, zz, xy, yz, zx) = this @ H.ravel() of a displacement
    gradient H (3, 3), H[i, c] = du_c/dx_i (the row-major order of :func:`strain_operator`'s gradients)."""
    T = np.zeros((6, 3, 3))
    for v, (i, c) in enumerate(((0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0))):
        T[v, i, c] = 1.0
        T[v, c, i] = 1.0
    return T.reshape(6, 9)


def jacobian(xyz: np.ndarray, dnat: np.ndarray):
    """J_ij = dx_j/dxi_i (ne, 3, 3), its determinant and inverse (closed-form 3x3 adjugate).

    ``xyz`` (ne, k, 3) node coordinates, ``dnat`` (3, k) shape-function derivatives at one point.
    """
    J = np.einsum("ia,eaj->eij", dnat, xyz)
    det, inv = det_inverse(J)
    return J, det, inv


def det_inverse(J: np.ndarray):
    """Determinants (...) and inverses (..., 3, 3) of 3x3 matrices ``J`` (..., 3, 3), closed-form adjugate
    (inf / nan where det = 0)."""
    a, b, c = J[..., 0, 0], J[..., 0, 1], J[..., 0, 2]
    d, e, f = J[..., 1, 0], J[..., 1, 1], J[..., 1, 2]
    g, h, k = J[..., 2, 0], J[..., 2, 1], J[..., 2, 2]
    adj = np.empty_like(J)
    adj[..., 0, 0], adj[..., 0, 1], adj[..., 0, 2] = e * k - f * h, c * h - b * k, b * f - c * e
    adj[..., 1, 0], adj[..., 1, 1], adj[..., 1, 2] = f * g - d * k, a * k - c * g, c * d - a * f
    adj[..., 2, 0], adj[..., 2, 1], adj[..., 2, 2] = d * h - e * g, b * g - a * h, a * e - b * d
    det = a * adj[..., 0, 0] + b * adj[..., 1, 0] + c * adj[..., 2, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = adj / det[..., None, None]
    return det, inv


def isotropic_pairs(X: np.ndarray, Y: np.ndarray, lam: float, mu: float) -> np.ndarray:
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


def as_matrix(K: np.ndarray) -> np.ndarray:
    """(ne, 3, 3, p, q) component pairs -> (ne, 3p, 3q) with dofs (field, component)."""
    ne, _, _, p, q = K.shape
    return K.transpose(0, 3, 1, 4, 2).reshape(ne, 3 * p, 3 * q)


def von_mises(stress: np.ndarray) -> np.ndarray:
    """Von Mises equivalent stress of Voigt stresses (..., 6) [Pa]."""
    sx, sy, sz, txy, tyz, tzx = np.moveaxis(stress, -1, 0)
    return np.sqrt(0.5 * ((sx - sy) ** 2 + (sy - sz) ** 2 + (sz - sx) ** 2)
                   + 3.0 * (txy ** 2 + tyz ** 2 + tzx ** 2))
