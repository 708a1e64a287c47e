"""Dense solves with S + diag(D) for a sequence of diagonals that differ in a few rows (penalty states).

The penalty path solves (S + diag(D)) x = b for open/closed states: D = k on closed rows, k_open on
open ones [N/m], and successive states (Newton iterations, increments, onset events) differ in a few
rows. One Cholesky factor of A0 = S + diag(D0) (the reference state) serves every D that differs
from D0 in at most ``max_rank`` rows J, by the Woodbury identity
    x = y - Z (diag(1 / (D_J - D0_J)) + Z_J)^-1 y_J,   y = A0^-1 b,   Z = A0^-1 E_J,
with the columns Z of A0^-1 cached per row (2 n^2 flops each, against n^3 / 3 for a factorisation).
Every such answer is checked by its residual (|b - (S + D) x| <= rtol max(|b|, |S x|, |D x|), the
scale of the terms that cancel; a direct solve meets it with room); a state farther than
``max_rank`` rows from D0, a capacitance that is not of the right inertia (S + diag(D) not positive definite) or a failed check
refactors at D (which becomes the reference, or reports that S + diag(D) is not positive definite).
``factorisations`` and ``solves`` count the work.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .linalg import cholesky_dense


class ShiftedSolver:
    """x = (S + diag(D))^-1 b for symmetric ``S`` (n, n) and diagonals ``D`` (n,) near a reference."""

    def __init__(self, S: np.ndarray, max_rank: int | None = None, rtol: float = 1e-11):
        self.S = S
        n = S.shape[0]
        self.max_rank = max(16, n // 8) if max_rank is None else max_rank
        self.rtol = rtol
        self.cf = None
        self.D0 = None
        self.cols: dict[int, np.ndarray] = {}
        self.factorisations = 0
        self.solves = 0

    def _refactor(self, D: np.ndarray) -> bool:
        self.factorisations += 1
        cf = cholesky_dense(self.S + np.diag(D))
        self.cf, self.D0, self.cols = cf, (None if cf is None else D.copy()), {}
        return cf is not None

    def _columns(self, J: np.ndarray) -> np.ndarray:
        missing = [j for j in J.tolist() if j not in self.cols]
        if missing:
            E = np.zeros((self.S.shape[0], len(missing)))
            E[missing, np.arange(len(missing))] = 1.0
            Z = sla.cho_solve(self.cf, E, check_finite=False)
            for c, j in enumerate(missing):
                self.cols[j] = Z[:, c]
        return np.column_stack([self.cols[j] for j in J.tolist()])

    def _corrected(self, D: np.ndarray, b: np.ndarray, J: np.ndarray) -> np.ndarray | None:
        y = sla.cho_solve(self.cf, b, check_finite=False)
        if J.size == 0:
            return y
        Z = self._columns(J)
        delta = D[J] - self.D0[J]
        w = _capacitance_solve(Z[J] + np.diag(1.0 / delta), delta > 0, y[J])
        if w is None:
            return None
        x = y - Z @ w
        Sx, Dx = self.S @ x, D * x
        res = np.linalg.norm(b - Sx - Dx)
        scale = max(np.linalg.norm(b), np.linalg.norm(Sx), np.linalg.norm(Dx))
        if not (np.isfinite(res) and res <= self.rtol * scale):
            return None
        return x

    def solve(self, D: np.ndarray, b: np.ndarray) -> np.ndarray | None:
        """Solution x, or None when S + diag(D) is not positive definite."""
        self.solves += 1
        D = np.asarray(D, float)
        if self.cf is None:
            if not self._refactor(D):
                return None
            return sla.cho_solve(self.cf, b, check_finite=False)
        J = np.flatnonzero(D != self.D0)
        if J.size <= self.max_rank:
            x = self._corrected(D, b, J)
            if x is not None:
                return x
        if not self._refactor(D):
            return None
        return sla.cho_solve(self.cf, b, check_finite=False)


def _capacitance_solve(M: np.ndarray, up: np.ndarray, r: np.ndarray) -> np.ndarray | None:
    """w = M^-1 r for the Woodbury capacitance M = diag(1 / delta) + Z_J, or None when S + diag(D)
    is not positive definite.

    Rows with delta > 0 (``up``, stiffer) give a positive definite block M_uu; S + diag(D) is positive
    definite exactly when the Schur complement C = M_dd - M_du M_uu^-1 M_ud of the softened rows is
    negative definite (A0 + updates is positive definite, and a downdate A1 - E c E^T keeps it so
    iff c^-1 - E^T A1^-1 E is). Both blocks are Cholesky factored, which tests it.
    """
    u, d = np.flatnonzero(up), np.flatnonzero(~up)
    if u.size:
        cu = cholesky_dense(M[np.ix_(u, u)])
        if cu is None:
            return None
        X = sla.cho_solve(cu, np.column_stack([M[np.ix_(u, d)], r[u]]), check_finite=False)
        Xd, xr = X[:, :-1], X[:, -1]
    else:
        cu, Xd, xr = None, np.zeros((0, d.size)), np.zeros(0)
    w = np.empty_like(r)
    if d.size:
        cd = cholesky_dense(M[np.ix_(u, d)].T @ Xd - M[np.ix_(d, d)])     # -C
        if cd is None:
            return None
        w[d] = -sla.cho_solve(cd, r[d] - M[np.ix_(d, u)] @ xr, check_finite=False)
    if u.size:
        w[u] = xr - Xd @ w[d]
    return w
