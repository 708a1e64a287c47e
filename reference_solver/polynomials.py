"""Nodal bases from monomials: the shape functions of an element (or face) with nodes at natural
coordinates ``nodes`` and polynomial space spanned by the monomials ``exps`` are N = P(xi) V^-1 with
V_im = P_m(node_i) (so N_a(node_b) = delta_ab). Exact up to round-off (~1e-15) for the spaces used here.
"""

from __future__ import annotations

import numpy as np


def monomials(xi: np.ndarray, exps: np.ndarray) -> np.ndarray:
    """P_m(xi) (p, m) at points ``xi`` (p, d) of monomials with exponents ``exps`` (m, d)."""
    xi = np.atleast_2d(np.asarray(xi, float))
    return np.prod(xi[:, None, :] ** exps[None, :, :], axis=2)


def monomial_gradients(xi: np.ndarray, exps: np.ndarray) -> np.ndarray:
    """dP_m/dxi_i (p, d, m) at points ``xi`` (p, d)."""
    xi = np.atleast_2d(np.asarray(xi, float))
    p, d = xi.shape
    out = np.empty((p, d, exps.shape[0]))
    for i in range(d):
        e = exps.copy()
        c = e[:, i].astype(float)
        e[:, i] = np.maximum(e[:, i] - 1, 0)
        out[:, i] = c[None, :] * monomials(xi, e)
    return out


class NodalBasis:
    """Shape functions N_a (and natural derivatives) of nodes ``nodes`` (k, d) over monomials ``exps``."""

    def __init__(self, nodes, exps):
        self.nodes = np.asarray(nodes, float)
        self.exps = np.asarray(exps, np.int64)
        self.coeff = np.linalg.inv(monomials(self.nodes, self.exps))       # (m, k)

    def values(self, xi) -> np.ndarray:
        """N_a (p, k) at points ``xi`` (p, d)."""
        return monomials(xi, self.exps) @ self.coeff

    def gradients(self, xi) -> np.ndarray:
        """dN_a/dxi_i (p, d, k) at points ``xi`` (p, d)."""
        return monomial_gradients(xi, self.exps) @ self.coeff


def exponents(terms: str) -> np.ndarray:
    """Exponents from a compact spelling: 'x2y' -> (2, 1, 0), '1' -> (0, 0, 0); space separated."""
    out = []
    for t in terms.split():
        e = [0, 0, 0]
        i = 0
        while t != "1" and i < len(t):
            axis = "xyz".index(t[i])
            i += 1
            power = int(t[i]) if i < len(t) and t[i].isdigit() else 1
            i += i < len(t) and t[i].isdigit()
            e[axis] += power
        out.append(e)
    return np.array(out, np.int64)
