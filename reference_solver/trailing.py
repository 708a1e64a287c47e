"""Trailing-block Schur complement built straight from the 3x3 node blocks (no sparse slicing).

For a distributing coupling the map u = T q is block diagonal (one 3x3 frame per node), so
T^T K T only changes the blocks of the framed (contact and spring) nodes, done in place on the
blocks. The fill-reducing order is computed on the node graph (CHOLMOD analyze on the n x n
pattern, 9x smaller than K) and expanded to the dofs, with the retained dofs r appended last.
The lower triangle of P (K + D0) P^T (D0 = diag(K) on r) is then written in one pass into CSC,
the blocks are released, and CHOLMOD factors it with the natural order; S + D0 = L_rr L_rr^T is
read from the trailing supernodes (linalg.schur_from_trailing_factor). One copy of K lives at a time.
"""

from __future__ import annotations

import time
import warnings

import numpy as np
import scipy.sparse as sp

from .assembly import BlockStiffness
from .errors import ReferenceSolverError
from .linalg import _SINGULAR, Schur, _cholmod, schur_from_trailing_factor
from .stages import mark

ORDERING = "default"   # CHOLMOD ordering method for the node graph (AMD, METIS when it is better)
# From this many nodes on the node graph is ordered by LARGE_ORDERING outright: CHOLMOD's default keeps AMD
# there (its test, flops / nnz(L) >= 500, is 3x smaller on the node graph than on the dof graph), and AMD's
# factor took 1.3-1.4x METIS's CPU at 205k dof (METIS itself +1 s). Below it (the pinned models) the
# ordering, and so the factor, stay as they were.
METIS_MIN_NODES = 20_000
# CHOLMOD's ordering of the node graph from METIS_MIN_NODES nodes on ("metis" or "nesdis"; both need a
# CHOLMOD built with METIS, without it CHOLMOD's default below). With the retained dofs moved last neither
# wins on every mesh: NESDIS took 10 % fewer flops at 400k (320x140x2), 1-3 % fewer on four shapes, 9 %
# more on 280x120x3 and 16 % more at 1M (500x220x2); see bench/README.md, "The retained dofs last".
LARGE_ORDERING = "metis"


def rotate_blocks(K: BlockStiffness, nodes: np.ndarray, R: np.ndarray) -> None:
    """In place: block (a, b) <- R_a^T K_ab R_b for the ``nodes`` with frames ``R`` (m, 3, 3)."""
    pos = np.full(K.n_nodes, -1, np.int64)
    pos[nodes] = np.arange(nodes.size)
    for side, idx_of in (("row", K.rows), ("col", K.cols)):
        sel = np.flatnonzero(pos[idx_of] >= 0)
        B = K.comp[:, sel].T.reshape(-1, 3, 3)
        Rk = R[pos[idx_of[sel]]]
        B = np.einsum("kji,kjl->kil", Rk, B) if side == "row" else B @ Rk
        K.comp[:, sel] = B.reshape(-1, 9).T


def node_order(K: BlockStiffness) -> np.ndarray:
    """Fill-reducing order of the nodes (new -> old) from CHOLMOD's analysis of the node graph."""
    return node_analysis(K)[0]


def node_analysis(K: BlockStiffness) -> tuple[np.ndarray, int | None]:
    """(order of the nodes new -> old, entries of the dof-level factor of that order or None) from one CHOLMOD
    analysis of the node graph (9 entries per node-factor entry; the retained dofs' trailing fill not counted)."""
    n = K.n_nodes
    indptr = np.searchsorted(K.rows, np.arange(n + 1)).astype(K.cols.dtype)
    G = sp.csc_matrix((np.ones(K.cols.size), K.cols, indptr), shape=(n, n))   # symmetric pattern
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", _cholmod.CholmodTypeConversionWarning)
        try:
            f = analyze_nodes(G, mode="supernodal")
        except _cholmod.CholmodError:
            raise ReferenceSolverError(_SINGULAR) from None
    entries = supernodal_size(f, n)
    return f.P(), (None if entries is None else 9 * entries)


def supernodal_size(f, n: int) -> int | None:
    """Entries (xsize) of the supernodal CHOLMOD factor or analysis ``f`` of an n x n matrix, read from the
    ``cholmod_factor`` struct (SuiteSparse 5 layout, every field checked); None where the layout is not the one
    expected."""
    import ctypes
    try:
        base = id(f)
        if ctypes.c_void_p.from_address(base + 16).value != id(f._common):
            return None
        L = ctypes.c_void_p.from_address(base + 24).value
        if ctypes.c_size_t.from_address(L).value != n or ctypes.c_int.from_address(L + 184).value != 1:
            return None
        return int(ctypes.c_size_t.from_address(L + 120).value)
    except Exception:                                                   # pragma: no cover - defensive
        return None


# CHOLMOD's int (32-bit) version overflows past 2^31 factor entries: "problem too large" in the supernodal
# symbolic analysis (measured: 1292 x 193 x 3, 3.0M dof, 1.99e9 entries estimated). From this many estimated
# entries the factorisation runs on CHOLMOD's long (64-bit) version (the same ordering and arithmetic).
LONG_INDEX_ENTRIES = 2**30


def analyze_nodes(G: sp.csc_matrix, **kw):
    """CHOLMOD ``analyze`` of a node graph ``G`` (n x n) with the ordering of the condensation:
    ``LARGE_ORDERING`` from ``METIS_MIN_NODES`` nodes on (CHOLMOD's default when it was built without METIS),
    else ``ORDERING``.
    ``kw`` goes to ``analyze`` (e.g. ``mode``); shared with the memory estimate (estimate.factor_entries)."""
    if ORDERING == "default" and G.shape[0] >= METIS_MIN_NODES:
        try:
            return _cholmod.analyze(G, ordering_method=LARGE_ORDERING, **kw)
        except _cholmod.CholmodError:                    # no METIS in this CHOLMOD: its default below
            pass
    return _cholmod.analyze(G, ordering_method=ORDERING, **kw)


def _lower_permuted(holder: list, iperm: np.ndarray, idx_t) -> sp.csc_matrix:
    """Lower triangle of P K P^T (K = ``holder.pop()``, released before the CSC conversion;
    ``iperm``: old dof -> new) in CSC with sorted rows, written once.

    The new dof numbers of the 3 row and 3 column components are gathered once each; each of the
    9 block components writes its lower entries straight into the coordinate arrays (no parts to
    concatenate), which CSC conversion then sorts.
    """
    K = holder.pop()
    gi = [iperm[3 * K.rows.astype(idx_t) + i] for i in range(3)]
    gj = [iperm[3 * K.cols.astype(idx_t) + j] for j in range(3)]
    low = [gi[c // 3] >= gj[c % 3] for c in range(9)]
    counts = [int(np.count_nonzero(m)) for m in low]
    nnz = sum(counts)
    rows, cols, vals = np.empty(nnz, idx_t), np.empty(nnz, idx_t), np.empty(nnz)
    at = 0
    for c in range(9):
        sl = slice(at, at + counts[c])
        np.compress(low[c], gi[c // 3], out=rows[sl])
        np.compress(low[c], gj[c % 3], out=cols[sl])
        np.compress(low[c], K.comp[c], out=vals[sl])
        low[c] = None
        at += counts[c]
    n3 = 3 * K.n_nodes
    del gi, gj, K
    Kp = sp.csc_matrix((vals, (rows, cols)), shape=(n3, n3))
    Kp.sort_indices()
    return Kp


def schur_blocks(holder: list, r: np.ndarray, F: np.ndarray) -> Schur:
    """Schur complement onto the dofs ``r`` of the block stiffness ``holder.pop()`` (released early).

    ``F`` (3n, ncase): load vectors in the same (rotated) dof numbering as the blocks.
    """
    if _cholmod is None:
        raise ReferenceSolverError("schur='trailing' needs CHOLMOD (scikit-sparse)")
    t0 = time.perf_counter()
    K = holder.pop()
    n3, nr = 3 * K.n_nodes, r.size
    diag = K.diagonal()
    d0 = diag[r]
    if np.any(d0 <= 0) or np.any(diag <= 0):
        raise ReferenceSolverError(_SINGULAR)
    isr = np.zeros(n3, bool)
    isr[r] = True
    order, entries = node_analysis(K)
    dofs = (3 * order[:, None] + np.arange(3)).ravel()
    use_long = entries is None and n3 > 2**24 or (entries or 0) + nr * (nr + 1) // 2 >= LONG_INDEX_ENTRIES
    perm = np.concatenate([dofs[~isr[dofs]], r])                     # new -> old
    idx_t = np.int32 if n3 < 2**31 - 1 else np.int64
    iperm = np.empty(n3, idx_t)
    iperm[perm] = np.arange(n3, dtype=idx_t)
    holder.append(K)
    del K
    Kp = _lower_permuted(holder, iperm, idx_t)                       # lower triangle of P K P^T
    head = Kp.indptr[n3 - nr:n3]                                     # sorted rows: diagonal first
    Kp.data[head] += d0[Kp.indices[head] - (n3 - nr)]                # K + D0 on r (ordered last)
    t1 = time.perf_counter()
    mark("split")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", _cholmod.CholmodTypeConversionWarning)
        try:
            f = _cholmod.cholesky(Kp, ordering_method="natural", mode="supernodal", use_long=use_long)
        except _cholmod.CholmodNotPositiveDefiniteError:
            raise ReferenceSolverError(_SINGULAR) from None
    del Kp
    t2 = time.perf_counter()
    mark("factor")
    sc = schur_from_trailing_factor(f, perm, r, F, d0, {"split_s": t1 - t0, "factor_s": t2 - t1}, t2)
    sc.method = "cholmod-trailing-blocks"
    mark("schur")
    return sc
