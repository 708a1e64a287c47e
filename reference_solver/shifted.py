"""Dense solves with S + diag(D) for a sequence of diagonals that differ in a few rows (penalty states).

The penalty path solves (S + diag(D)) x = b for open/closed states: D = k on closed rows, k_open on
open ones [N/m], and successive states (Newton iterations, increments, onset events) differ in a few
rows. One Cholesky factor of A0 = S + diag(D0) (the reference state) serves every D that differs
from D0 in at most ``max_rank`` rows J, by the Woodbury identity
    x = y - Z (diag(1 / (D_J - D0_J)) + Z_J)^-1 y_J,   y = A0^-1 b,   Z = A0^-1 E_J,
with the columns Z of A0^-1 cached per row (2 n^2 flops each, against n^3 / 3 for a factorisation).
Every such answer is checked by its residual (|b - (S + D) x| <= rtol max(|b|, |S x|, |D x|), the
scale of the terms that cancel; a direct solve meets it with room); a state farther than
``max_rank`` rows from D0, a capacitance that is not of the right inertia (S + diag(D) not positive
definite) or a failed check refactors at D (which becomes the reference, or reports that
S + diag(D) is not positive definite).
``factorisations`` and ``solves`` count the work of one solver; ``COUNTS`` sums them over all
solvers of the process (bench/scale.py prints it per method).
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from .linalg import cholesky_dense

COUNTS = {"factorisations": 0, "solves": 0}   # dense factorisations and solves, all solvers


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
        COUNTS["factorisations"] += 1
        self.cf, self.cols = None, {}                # the old factor goes before the new one is made (one n x n)
        A = self.S.copy()
        A[np.diag_indices_from(A)] += D
        cf = cholesky_dense(A, overwrite=True)
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
        COUNTS["solves"] += 1
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


class SubsetSolver:
    """x = S_II^-1 b for principal submatrices of a symmetric positive definite ``S`` (n, n) whose
    index sets ``I`` (the open rows of the Lagrange method) differ from a reference I0 in a few rows.

    One Cholesky factor of S_00 (rows I0) serves I = I0 - R + A (R removed, A added, at most
    ``max_rank`` together, by default |I0| / 6): x_A and multipliers mu holding x_R = 0 solve the
    small bordered system
        [ S_AA - S_A0 Z_A    -Z_A[R]^T ] [x_A]   [ b_A - S_A0 y ]
        [ -Z_A[R]            -W_RR     ] [mu ] = [ -y_R         ]
    with y = S_00^-1 b (0 on R), Z_A = S_00^-1 S_0A, W_RR = (S_00^-1)_RR (columns cached), then
    x_0 = y - Z_A x_A - S_00^-1 E_R mu. Checked by its residual like ``ShiftedSolver``; otherwise
    S_II is factored and becomes the reference.
    """

    def __init__(self, S: np.ndarray, max_rank: int | None = None, rtol: float = 1e-11):
        self.S = S
        self.n = S.shape[0]
        self.max_rank = max_rank          # None: max(8, |I0| / 6) (columns cost 2 |I0|^2, a factor |I0|^3 / 3)
        self.rtol = rtol
        self.cf = None
        self.idx0 = None
        self.pos0 = np.full(self.n, -1)
        self.cols: dict[tuple[str, int], np.ndarray] = {}
        self.factorisations = 0
        self.solves = 0

    def _refactor(self, I: np.ndarray) -> bool:
        self.factorisations += 1
        COUNTS["factorisations"] += 1
        self.cf, self.cols = None, {}                # the old factor goes before the new one is made
        self.cf = cholesky_dense(self.S[np.ix_(I, I)], overwrite=True) if I.size else None
        self.idx0, self.cols = (I.copy() if self.cf is not None else None), {}
        self.pos0[:] = -1
        if self.cf is not None:
            self.pos0[I] = np.arange(I.size)
        return self.cf is not None

    def _columns(self, kind: str, J: np.ndarray) -> np.ndarray:
        missing = [j for j in J.tolist() if (kind, j) not in self.cols]
        if missing:
            if kind == "a":                                     # S_00^-1 S_0j
                E = self.S[np.ix_(self.idx0, missing)]
            else:                                               # S_00^-1 e_j
                E = np.zeros((self.idx0.size, len(missing)))
                E[self.pos0[missing], np.arange(len(missing))] = 1.0
            Z = sla.cho_solve(self.cf, E, check_finite=False)
            for c, j in enumerate(missing):
                self.cols[(kind, j)] = Z[:, c]
        return np.column_stack([self.cols[(kind, j)] for j in J.tolist()]) if J.size else np.zeros((self.idx0.size, 0))

    def _bordered(self, I: np.ndarray, b: np.ndarray, add: np.ndarray, rem: np.ndarray) -> np.ndarray | None:
        bfull = np.zeros(self.n)
        bfull[I] = b
        y = sla.cho_solve(self.cf, bfull[self.idx0], check_finite=False)
        if add.size == 0 and rem.size == 0:
            return y
        ZA, ZR = self._columns("a", add), self._columns("r", rem)
        pr = self.pos0[rem]
        SA0 = self.S[np.ix_(add, self.idx0)]
        na = add.size
        H = np.empty((na + rem.size,) * 2)
        H[:na, :na] = self.S[np.ix_(add, add)] - SA0 @ ZA
        H[na:, :na] = -ZA[pr]
        H[:na, na:] = -ZA[pr].T
        H[na:, na:] = -ZR[pr]
        rhs = np.concatenate([bfull[add] - SA0 @ y, -y[pr]])
        try:
            s = np.linalg.solve(H, rhs)
        except np.linalg.LinAlgError:
            return None
        x = np.zeros(self.n)
        x[self.idx0] = y - ZA @ s[:na] - ZR @ s[na:]
        x[add] = s[:na]
        Sx = (self.S @ x)[I]
        res = np.linalg.norm(b - Sx)
        if not (np.isfinite(res) and res <= self.rtol * max(np.linalg.norm(b), np.linalg.norm(Sx))):
            return None
        return x[I]

    def solve(self, I: np.ndarray, b: np.ndarray) -> np.ndarray | None:
        """x on the sorted index set ``I`` for ``b`` on ``I``, or None when S_II is not positive definite."""
        self.solves += 1
        COUNTS["solves"] += 1
        I = np.asarray(I)
        if I.size == 0:
            return np.zeros(0)
        if self.cf is not None:
            inI = np.zeros(self.n, bool)
            inI[I] = True
            add = I[self.pos0[I] < 0]
            rem = self.idx0[~inI[self.idx0]]
            limit = max(8, self.idx0.size // 6) if self.max_rank is None else self.max_rank
            if add.size + rem.size <= limit:
                x = self._bordered(I, b, add, rem)
                if x is not None:
                    return x
        if not self._refactor(I):
            return None
        return sla.cho_solve(self.cf, b, check_finite=False)
