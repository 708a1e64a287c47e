"""Sparse factorisations (injectable) and the Schur complement onto the retained dofs.

A factorisation is a callable ``factorize(K) -> solve`` where ``K`` is a symmetric positive
definite sparse matrix and ``solve(B)`` returns K^-1 B for a vector or an (n, k) array.
``cholmod_factorize`` (scikit-sparse, CHOLMOD) is the default when installed, ``splu_factorize``
(SciPy SuperLU) the fallback. Each is factored once and re-used for every right-hand side.

The Schur complement S = K_rr - K_ri K_ii^-1 K_ir onto the retained dofs r is built either
- ``trailing`` (CHOLMOD only): factor K + D0 (D0 = diag(K) on r) with r ordered last after a
  fill-reducing ordering of K_ii; the trailing block of the factor gives S + D0 = L_rr L_rr^T. Cost about
  one factorisation; or
- ``rhs`` (any factorisation): factor K_ii and solve for the columns of K_ir in blocks.
"""

from __future__ import annotations

import ctypes
import gc
import os
import sys
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import ReferenceSolverError

try:  # CHOLMOD through scikit-sparse (needs SuiteSparse); optional
    from sksparse import cholmod as _cholmod
except ImportError:  # pragma: no cover - depends on the installation
    _cholmod = None

HAVE_CHOLMOD = _cholmod is not None
Solve = Callable[[np.ndarray], np.ndarray]
Factorize = Callable[[sp.spmatrix], Solve]

_SINGULAR = ("mechanism: the stiffness matrix is singular with the contact and spring dofs held "
             "(a part of the mesh is not connected or not restrained)")


def keep_factor_out_of_gc(f):
    """Untrack a scikit-sparse 0.4 ``Factor`` from the cyclic garbage collector; returns ``f``.

    sksparse 0.4's ``Factor.__dealloc__`` frees the factor with ``&self._common._common``, and the
    class does not opt out of ``tp_clear``. When the collector breaks a reference cycle that holds a
    Factor (a closure cell of ``Schur.recover`` in a dead system, the last collection at exit) it may
    clear the Factor first, which sets ``_common`` to None; the dealloc then hands CHOLMOD a pointer
    24 bytes into ``Py_None`` (libpython's static data): CHOLMOD finds no valid ``itype`` there and
    writes ``status = CHOLMOD_INVALID`` (-4) over the next static object, ``PyLongRangeIter_Type``'s
    static-type index in Python 3.12, and the interpreter crashes at exit (the factor also leaks).
    A Factor refers only to its Common, which refers to nothing, so no cycle passes through it:
    untracked it is freed by reference counting alone, with ``_common`` intact.
    """
    if (_cholmod is not None and type(f) is getattr(_cholmod, "Factor", None) and gc.is_tracked(f)
            and sys.implementation.name == "cpython"):
        _gc_untrack(f)
    return f


def _gc_untrack(obj) -> None:
    untrack = ctypes.pythonapi.PyObject_GC_UnTrack
    untrack.argtypes, untrack.restype = [ctypes.py_object], None
    untrack(obj)


def cholmod_factorize(K: sp.spmatrix) -> Solve:
    """CHOLMOD supernodal Cholesky (fill-reducing ordering chosen by CHOLMOD)."""
    if _cholmod is None:
        raise ReferenceSolverError("CHOLMOD is not installed (pip install 'scikit-sparse<0.5')")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", _cholmod.CholmodTypeConversionWarning)
            f = _cholmod.cholesky(sp.csc_matrix(K))
    except _cholmod.CholmodNotPositiveDefiniteError:
        raise ReferenceSolverError(_SINGULAR) from None
    return keep_factor_out_of_gc(f)


def splu_factorize(K: sp.spmatrix) -> Solve:
    """SciPy SuperLU (symmetric-pattern ordering), the fallback without CHOLMOD."""
    try:
        lu = spla.splu(sp.csc_matrix(K), permc_spec="MMD_AT_PLUS_A")
    except RuntimeError:
        raise ReferenceSolverError(_SINGULAR) from None
    return lu.solve


def default_factorize() -> Factorize:
    return cholmod_factorize if HAVE_CHOLMOD else splu_factorize


def factorize_name(factorize: Factorize) -> str:
    known = {cholmod_factorize: "cholmod", splu_factorize: "superlu"}
    return known.get(factorize, getattr(factorize, "__name__", "custom"))


@dataclass
class Schur:
    """Condensation of K onto the retained dofs r for the load vectors ``F`` (n, ncase).

    ``S``: (nr, nr); ``fhat``: (nr, ncase) condensed loads f_r - K_ri K_ii^-1 f_i;
    ``recover(u_r, coeffs)``: the full displacement for retained values u_r under sum_k coeffs_k F_k
    (one solve; u_r (nr, m) and coeffs (ncase, m) recover m states at once).
    """
    S: np.ndarray
    fhat: np.ndarray
    recover: Callable[[np.ndarray, np.ndarray], np.ndarray]
    method: str
    timings: dict = field(default_factory=dict)
    recover_diagonal: np.ndarray | None = None     # (nr,) what ``recover`` adds to S's diagonal (trailing: D0)
    recover_uses_S: bool = True                    # False: ``recover`` reads the factor only (S may be dropped)

    def add_diagonal(self, rows: np.ndarray, values: np.ndarray) -> None:
        """S[rows, rows] += values in place (the springs of the condensation: no second nr x nr copy of S), the
        recovery unchanged: it still applies the condensed stiffness of the factor, (S - diag(values)) + D0."""
        self.S[rows, rows] += values
        if self.recover_diagonal is not None:
            self.recover_diagonal[rows] -= values


def _split(K: sp.spmatrix, r: np.ndarray):
    n = K.shape[0]
    mask = np.ones(n, bool)
    mask[r] = False
    i = np.flatnonzero(mask)
    return i


def schur_rhs(K: sp.spmatrix, r: np.ndarray, F: np.ndarray, factorize: Factorize,
              block: int = 256) -> Schur:
    """Factor K_ii with ``factorize`` and solve for the columns of K_ir in blocks of ``block``."""
    t0 = time.perf_counter()
    K = sp.csr_matrix(K)
    n = K.shape[0]
    i = _split(K, r)
    Ki = K[i]
    Kii = Ki[:, i].tocsc()
    Kir = Ki[:, r].tocsc()
    del Ki
    Krr = K[r][:, r].toarray()
    del K
    t1 = time.perf_counter()
    solve = factorize(Kii)
    t2 = time.perf_counter()
    S = Krr.copy()
    for b in range(0, r.size, block):
        X = np.asarray(solve(Kir[:, b:b + block].toarray()))
        S[:, b:b + block] -= Kir.T @ X
    V = np.asarray(solve(np.ascontiguousarray(F[i]))).reshape(i.size, -1)   # K_ii^-1 f_i per case
    fhat = F[r] - Kir.T @ V
    t3 = time.perf_counter()

    def recover(u_r: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        u = np.empty((n,) + np.shape(u_r)[1:])
        u[r] = u_r
        u[i] = V @ coeffs - np.asarray(solve(Kir @ u_r)).reshape(u[i].shape)
        return u

    return Schur(0.5 * (S + S.T), fhat, recover, f"rhs:{factorize_name(factorize)}",
                 {"split_s": t1 - t0, "factor_s": t2 - t1, "schur_s": t3 - t2}, recover_uses_S=False)


def schur_trailing(K: sp.spmatrix, r: np.ndarray, F: np.ndarray) -> Schur:
    """CHOLMOD factor of K + D0 with the retained dofs ordered last; S from the trailing block.

    ``K`` is symmetric; the caller should not keep another reference to it (it is released as soon
    as the permuted copy exists, to lower the peak memory).
    """
    if _cholmod is None:
        raise ReferenceSolverError("schur='trailing' needs CHOLMOD (scikit-sparse)")
    t0 = time.perf_counter()
    K = sp.csr_matrix(K)
    n, nr = K.shape[0], r.size
    i = _split(K, r)
    d0 = K.diagonal()[r]
    if np.any(d0 <= 0):
        raise ReferenceSolverError(_SINGULAR)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", _cholmod.CholmodTypeConversionWarning)
        Kii = K[i][:, i]
        Kii.sort_indices()
        try:                                                         # fill-reducing order of K_ii
            order = _cholmod.analyze(sp.csc_matrix((Kii.data, Kii.indices, Kii.indptr), shape=Kii.shape)).P()
        except _cholmod.CholmodError:
            raise ReferenceSolverError(_SINGULAR) from None
        del Kii
        perm = np.concatenate([i[order], r])
        Kp = (K + sp.csr_matrix((d0, (r, r)), shape=K.shape))[perm][:, perm]
        del K
        Kp.sort_indices()
        Kp = sp.csc_matrix((Kp.data, Kp.indices, Kp.indptr), shape=Kp.shape)  # symmetric: CSR = CSC^T
        t1 = time.perf_counter()
        try:
            f = _cholmod.cholesky(Kp, ordering_method="natural")
        except _cholmod.CholmodNotPositiveDefiniteError:
            raise ReferenceSolverError(_SINGULAR) from None
        del Kp
    t2 = time.perf_counter()
    return schur_from_trailing_factor(f, perm, r, F, d0, {"split_s": t1 - t0, "factor_s": t2 - t1}, t2)


def trailing_block(f, n: int, nr: int) -> np.ndarray | None:
    """Dense trailing block L[n-nr:, n-nr:] of a supernodal CHOLMOD factor, read in place.

    scikit-sparse 0.4 does not expose the supernodes and ``Factor.L()`` copies (and converts) the
    whole factor, which at millions of dofs costs as much memory as the factor itself. The block is
    read from the ``cholmod_factor`` struct (SuiteSparse 5 layout) with ctypes; every field read is
    checked (dimension, supernodal LL', real double, index type, last supernode ends at n), and
    None is returned when anything does not match (the caller then uses ``f.L()``).
    """
    if os.environ.get("REFERENCE_SOLVER_NO_SUPERNODE_READ"):
        return None
    try:
        import sksparse
        if not str(getattr(sksparse, "__version__", "")).startswith("0.4."):
            return None
        if type(f).__basicsize__ < 32:
            return None
        base = id(f)
        if ctypes.c_void_p.from_address(base + 16).value != id(f._common):   # layout: _common, _factor
            return None
        L = ctypes.c_void_p.from_address(base + 24).value
        if not L:
            return None
        size_t = lambda off: ctypes.c_size_t.from_address(L + off).value      # noqa: E731
        cint = lambda off: ctypes.c_int.from_address(L + off).value           # noqa: E731
        ptr = lambda off: ctypes.c_void_p.from_address(L + off).value         # noqa: E731
        if size_t(0) != n or cint(180) != 1 or cint(184) != 1 or cint(196) != 1 or cint(200) != 0:
            return None                                       # n, is_ll, is_super, xtype real, double
        itype = cint(192)
        if itype not in (0, 2):
            return None
        it = ctypes.c_int32 if itype == 0 else ctypes.c_int64
        nsuper = size_t(104)
        as_np = lambda addr, ct, count: np.ctypeslib.as_array((ct * count).from_address(addr))  # noqa: E731
        sup = as_np(ptr(144), it, nsuper + 1)
        pi = as_np(ptr(152), it, nsuper + 1)
        px = as_np(ptr(160), it, nsuper + 1)
        if int(sup[-1]) != n or int(sup[0]) != 0:
            return None
        s_addr, x_addr = ptr(168), ptr(64)
        lo = n - nr
        out = np.zeros((nr, nr))
        k = int(np.searchsorted(sup, lo, side="right")) - 1            # supernode holding column lo
        for k in range(k, nsuper):
            c0, c1 = int(sup[k]), int(sup[k + 1])
            nrow = int(pi[k + 1] - pi[k])
            rows = as_np(s_addr + int(pi[k]) * ctypes.sizeof(it), it, nrow).astype(np.int64)
            blk = as_np(x_addr + int(px[k]) * 8, ctypes.c_double, nrow * (c1 - c0)).reshape(c1 - c0, nrow)
            for j in range(max(c0, lo), c1):                         # column j of L: rows >= j
                col = blk[j - c0]
                keep = rows >= j
                out[rows[keep] - lo, j - lo] = col[keep]
        return out
    except Exception:                                                  # pragma: no cover - defensive
        return None


def schur_from_trailing_factor(f, perm: np.ndarray, r: np.ndarray, F: np.ndarray, d0: np.ndarray,
                               timings: dict, t2: float) -> Schur:
    """S, condensed loads and recovery from a factor of P (K + D0) P^T with r = perm[n-nr:] last."""
    keep_factor_out_of_gc(f)                                         # captured by recover below
    n, nr = perm.size, r.size
    P = f.P()
    tail = P[n - nr:]
    if not np.array_equal(np.sort(tail), np.arange(n - nr, n)):   # CHOLMOD moved r: not expected
        raise ReferenceSolverError("schur='trailing': CHOLMOD reordered the retained dofs (use schur='rhs')")
    Lrr = trailing_block(f, n, nr)
    how = "supernodes"
    if Lrr is None:
        L = f.L()                                                    # converts the factor to simplicial
        p0 = int(L.indptr[n - nr])                                   # columns n-nr.. hold rows n-nr.. only
        Lrr = sp.csc_matrix((L.data[p0:], L.indices[p0:] - (n - nr), L.indptr[n - nr:] - p0),
                            shape=(nr, nr)).toarray()
        del L
        how = "L()"
    C = gram_lower(Lrr)                                              # S + D0 in the order tail
    back = np.empty(nr, np.int64)
    back[tail - (n - nr)] = np.arange(nr)
    S = C if np.array_equal(back, np.arange(nr)) else C[np.ix_(back, back)]    # S + D0, order of r
    del C
    S[np.diag_indices(nr)] -= d0                                     # S, exactly symmetric; S + D0 = S + d0 I
    dd = np.array(d0, float)                 # D0, less what Schur.add_diagonal adds to S in place later

    def SD_times(x: np.ndarray) -> np.ndarray:                      # (S + D0) x without a second nr x nr array
        return S @ x + dd.reshape((nr,) + (1,) * (np.ndim(x) - 1)) * x

    def solve_aug(b_perm: np.ndarray) -> np.ndarray:
        return np.asarray(f(b_perm))

    ni = n - nr
    Fi = F[perm[:ni]]
    B = np.zeros((n, F.shape[1]))
    B[:ni] = Fi
    # with the natural order kept (P = I): L^-1 [0; v] = [0; L_rr^-1 v], so every solve with a
    # right-hand side [f_i; v] is the stored forward part Z0 = L^-1 [f_i; 0] plus [0; L_rr^-1 v]
    # and one back substitution; the tail of (K + D0)^-1 [f_i; 0] is L_rr^-T Z0_r
    half = how == "supernodes" and np.array_equal(P, np.arange(n))
    if half:
        Z0 = np.asarray(f.solve_L(B, use_LDLt_decomposition=False)).reshape(n, -1)
        Y = sla.solve_triangular(Lrr, Z0[ni:], lower=True, trans="T", check_finite=False)
        del Lrr                                    # not held through the path: re-read from the factor when recovering
    else:
        Y = solve_aug(B)[ni:].reshape(nr, -1)                        # y = -(S+D0)^-1 K_ri K_ii^-1 f_i
    fhat = F[r] + SD_times(Y)
    t3 = time.perf_counter()

    def recover_half(u_r: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        # L_rr^-1 (S + D0) w = L_rr^T w (S + D0 = L_rr L_rr^T): neither S nor a triangular solve, the trailing
        # block re-read from the factor for the call
        shape = (n,) + np.shape(u_r)[1:]
        z = Z0 @ coeffs
        z[ni:] += trailing_block(f, n, nr).T @ (u_r - Y @ coeffs)
        u = np.empty(shape)
        u[perm] = np.asarray(f.solve_Lt(z, use_LDLt_decomposition=False)).reshape(shape)
        return u

    def recover(u_r: np.ndarray, coeffs: np.ndarray) -> np.ndarray:
        shape = (n,) + np.shape(u_r)[1:]
        u, b = np.empty(shape), np.empty(shape)
        b[:ni] = Fi @ coeffs
        b[ni:] = SD_times(u_r - Y @ coeffs)
        u[perm] = solve_aug(b).reshape(shape)
        return u

    return Schur(S, fhat, recover_half if half else recover, "cholmod-trailing",
                 {**timings, "schur_s": t3 - t2, "trailing_read": how}, recover_diagonal=dd, recover_uses_S=not half)


def gram_lower(L: np.ndarray, block: int = 1024) -> np.ndarray:
    """L L^T (m, m) for a square L, exactly symmetric: BLAS dsyrk writes one triangle (half the flops of
    L @ L.T and no transposed copy of L), the other is mirrored block by block (no index arrays)."""
    m = L.shape[0]
    if m == 0:
        return np.zeros((0, 0))
    C = sla.blas.dsyrk(1.0, np.asarray(L, float).T, trans=1, lower=0)     # upper triangle of L L^T, Fortran order
    for b in range(0, m, block):
        e = min(b + block, m)
        C[b:e, :b] = C[:b, b:e].T                                     # rows b:e left of the diagonal block
        blk = C[b:e, b:e]
        lower = np.tril_indices(e - b, -1)
        blk[lower] = blk.T[lower]
    return C


def cholesky_dense(A: np.ndarray, overwrite: bool = False):
    """Dense Cholesky factor (scipy cho_factor, lower) or None when A is not positive definite;
    ``overwrite``: the factor may be written over ``A`` (a fresh array of the caller's)."""
    try:
        return sla.cho_factor(A, lower=True, overwrite_a=overwrite, check_finite=False)
    except (np.linalg.LinAlgError, sla.LinAlgError):
        return None

