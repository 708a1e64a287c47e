"""Global stiffness assembly: element matrices in batches, summed by 3x3 node blocks, then CSR.

Generic over the element type (:mod:`reference_solver.elements`): each block of elements of one type
is assembled with its own element object, vectorised over the block; a mixed mesh is several blocks
(:func:`assemble_problem_blocks`). ``hexes`` below is any (m, n) connectivity of the ``element``.
Duplicates are summed on node pairs (n^2 per element instead of 9 n^2 scalar entries): the node pairs
are found once (``node_pairs``, linear passes), the 9 block components are summed with np.bincount
over the range of pairs a batch touches, giving the block form (node pairs sorted by row, then column).
``assemble_stiffness`` converts it to CSR; the condensation works on the blocks directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .elements import element_type

try:  # compiled COO -> CSR and per-row sort of SciPy (private module, stable since SciPy 1.8)
    from scipy.sparse import _sparsetools
except ImportError:  # pragma: no cover - depends on the SciPy version
    _sparsetools = None

# elements per batch of element matrices: at 2048 each temporary stays under glibc's 32 MB mmap threshold,
# so freed blocks are reused instead of page-faulted afresh (8192: 1.4x the CPU, bench/README.md)
CHUNK = 2048


def element_dofs(hexes: np.ndarray) -> np.ndarray:
    """Global dof numbers (ne, 3n) of elements with connectivity ``hexes`` (ne, n): 3 * node + component."""
    h = np.asarray(hexes, np.int64)
    return (3 * h[:, :, None] + np.arange(3)).reshape(len(h), 3 * h.shape[1])


@dataclass
class BlockStiffness:
    """K as 3x3 node blocks: block k couples node ``rows[k]`` to node ``cols[k]`` [N/m].

    Pairs are sorted by (row, column) and unique; both (a, b) and (b, a) are present (K symmetric).
    ``comp[3 i + j, k]`` is entry (i, j) of block k (component-major, one array of 9 x nb floats).
    """
    n_nodes: int
    rows: np.ndarray              # (nb,) int32/int64
    cols: np.ndarray              # (nb,)
    comp: np.ndarray              # (9, nb)

    def diagonal(self) -> np.ndarray:
        """Diagonal of K (3n,) in dof order 3 * node + component."""
        d = np.zeros((self.n_nodes, 3))
        on = np.flatnonzero(self.rows == self.cols)
        for i in range(3):
            d[self.rows[on], i] = self.comp[4 * i, on]
        return d.ravel()

    def tocsr(self) -> sp.csr_matrix:
        n = self.n_nodes
        idx_t = np.int32 if 9 * self.rows.size < 2**31 - 1 and 3 * n < 2**31 - 1 else np.int64
        indptr = np.searchsorted(self.rows, np.arange(n + 1))
        blocks = np.ascontiguousarray(self.comp.T).reshape(-1, 3, 3)
        return sp.bsr_matrix((blocks, self.cols.astype(idx_t), indptr.astype(idx_t)),
                             shape=(3 * n, 3 * n)).tocsr()


def node_pairs(hexes, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique node pairs (rows, cols) of the elements, sorted by (row, column), and for each of the
    k^2 pairs (a, b) of every element (element-major) its index among them.

    ``hexes``: one connectivity (m, k), or a list of them (the blocks of a mixed mesh: the pair
    indices of the blocks follow each other in block order). Two linear passes of SciPy's compiled
    sparse kernels (coordinates to CSR by rows, then each row's columns sorted), instead of sorting
    all pair keys: the same arrays as ``np.unique`` of the keys a n + b, which is the fallback.
    """
    blocks = [np.asarray(h) for h in hexes] if isinstance(hexes, (list, tuple)) else [np.asarray(hexes)]
    N = sum(h.shape[0] * h.shape[1] ** 2 for h in blocks)
    node_t = np.int32 if n < 2**31 - 1 else np.int64
    idx_t = np.int32 if N < 2**31 - 1 and n < 2**31 - 1 else np.int64
    if _sparsetools is None:                                      # pragma: no cover - old SciPy
        key = np.concatenate([(h[:, :, None].astype(np.int64) * n + h[:, None, :]).ravel() for h in blocks])
        uniq, inv = np.unique(key, return_inverse=True)
        rows, cols = np.divmod(uniq, n)
        return rows.astype(node_t), cols.astype(node_t), inv.astype(idx_t)
    hs = [np.asarray(h, idx_t) for h in blocks]
    if len(hs) == 1:
        (h,) = hs
        ne, k = h.shape
        ri = np.broadcast_to(h[:, :, None], (ne, k, k)).ravel()
        ci = np.broadcast_to(h[:, None, :], (ne, k, k)).ravel()
    else:
        ri = np.concatenate([np.broadcast_to(h[:, :, None], (len(h), h.shape[1], h.shape[1])).ravel() for h in hs])
        ci = np.concatenate([np.broadcast_to(h[:, None, :], (len(h), h.shape[1], h.shape[1])).ravel() for h in hs])
    indptr, cols, entry = np.empty(n + 1, idx_t), np.empty(N, idx_t), np.empty(N, idx_t)
    _sparsetools.coo_tocsr(n, n, N, ri, ci, np.arange(N, dtype=idx_t), indptr, cols, entry)
    del ri, ci
    _sparsetools.csr_sort_indices(n, indptr, cols, entry)
    first = np.ones(N, bool)                                        # first entry of each pair
    np.not_equal(cols[1:], cols[:-1], out=first[1:])
    first[indptr[:-1][indptr[:-1] < N]] = True
    inv = np.empty(N, idx_t)
    inv[entry] = np.cumsum(first, dtype=idx_t) - 1
    del entry
    rows = np.repeat(np.arange(n, dtype=node_t), np.diff(indptr))[first]
    return rows, cols[first].astype(node_t, copy=False), inv


def assemble_element_blocks(nodes: np.ndarray, blocks, E: float, nu: float, chunk: int = CHUNK) -> BlockStiffness:
    """Global stiffness of a mesh given as ``blocks`` [(element, cells), ...] (element object or name;
    cells (m, k)), as summed 3x3 node blocks: each block vectorised with its own element type, in
    batches of about ``chunk`` 8-node elements' worth of entries (no Python loop per element)."""
    n = nodes.shape[0]
    blocks = [(element_type(el), np.asarray(c, np.int64)) for el, c in blocks]
    rows, cols, inv = node_pairs([c for _, c in blocks], n)
    comp = np.zeros((9, rows.size))
    off = 0
    for el, cells in blocks:
        k2 = el.n_nodes ** 2
        step = max(1, chunk * 64 // k2)
        for s in range(0, len(cells), step):
            ke = el.stiffness_pairs(nodes[cells[s:s + step]], E, nu)          # (m, 3, 3, k, k)
            m = ke.shape[0]
            kb = ke.reshape(m, 9, k2)
            sel = inv[off + k2 * s:off + k2 * (s + m)]
            lo, hi = int(sel.min()), int(sel.max()) + 1                     # pairs this batch touches
            loc = sel - lo
            for c in range(9):
                comp[c, lo:hi] += np.bincount(loc, weights=kb[:, c].ravel(), minlength=hi - lo)
        off += k2 * len(cells)
    del inv
    return BlockStiffness(n, rows, cols, comp)


def assemble_blocks(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                    element="c3d8i", chunk: int = CHUNK) -> BlockStiffness:
    """Global stiffness of a one-type mesh (connectivity ``hexes`` (m, k) of ``element``) as summed
    3x3 node blocks."""
    return assemble_element_blocks(nodes, [(element, hexes)], E, nu, chunk)


def assemble_problem_blocks(p, chunk: int = CHUNK) -> BlockStiffness:
    """Global stiffness of problem ``p`` (every element block of ``p.blocks``) as 3x3 node blocks."""
    return assemble_element_blocks(p.nodes, [(b.element, b.cells) for b in p.blocks], p.E, p.nu, chunk)


def assemble_stiffness(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                       element="c3d8i", chunk: int = CHUNK) -> sp.csr_matrix:
    """Global stiffness (3n x 3n, CSR) of a one-type mesh [N/m]."""
    return assemble_blocks(nodes, hexes, E, nu, element, chunk).tocsr()
