"""Global stiffness assembly: element matrices in batches, summed by 3x3 node blocks, then CSR.

Duplicates are summed on node pairs (64 per element instead of 576 scalar entries): the node pairs
are found once (``node_pairs``, linear passes), the 9 block components are summed with np.bincount
over the range of pairs a batch touches, giving the block form (node pairs sorted by row, then column).
``assemble_stiffness`` converts it to CSR; the condensation works on the blocks directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .elements import hex8_stiffness_pairs

try:  # compiled COO -> CSR and per-row sort of SciPy (private module, stable since SciPy 1.8)
    from scipy.sparse import _sparsetools
except ImportError:  # pragma: no cover - depends on the SciPy version
    _sparsetools = None

CHUNK = 8192  # elements per batch of element matrices


def element_dofs(hexes: np.ndarray) -> np.ndarray:
    """Global dof numbers (ne, 24) of hexahedra: 3 * node + component."""
    return (3 * np.asarray(hexes, np.int64)[:, :, None] + np.arange(3)).reshape(len(hexes), 24)


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


def node_pairs(hexes: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unique node pairs (rows, cols) of the hexahedra, sorted by (row, column), and for each of the
    64 pairs (a, b) of every element (element-major) its index among them.

    Two linear passes of SciPy's compiled sparse kernels (coordinates to CSR by rows, then each row's
    columns sorted; a row holds at most 64 x its elements), instead of sorting all 64 ne pair keys:
    the same arrays as ``np.unique`` of the keys a n + b, which is the fallback.
    """
    ne = len(hexes)
    N = 64 * ne
    node_t = np.int32 if n < 2**31 - 1 else np.int64
    idx_t = np.int32 if N < 2**31 - 1 and n < 2**31 - 1 else np.int64
    if _sparsetools is None:                                      # pragma: no cover - old SciPy
        key = (hexes[:, :, None] * n + hexes[:, None, :]).ravel()
        uniq, inv = np.unique(key, return_inverse=True)
        rows, cols = np.divmod(uniq, n)
        return rows.astype(node_t), cols.astype(node_t), inv.astype(idx_t)
    h = np.asarray(hexes, idx_t)
    indptr, cols, entry = np.empty(n + 1, idx_t), np.empty(N, idx_t), np.empty(N, idx_t)
    _sparsetools.coo_tocsr(n, n, N, np.broadcast_to(h[:, :, None], (ne, 8, 8)).ravel(),
                           np.broadcast_to(h[:, None, :], (ne, 8, 8)).ravel(),
                           np.arange(N, dtype=idx_t), indptr, cols, entry)
    _sparsetools.csr_sort_indices(n, indptr, cols, entry)
    first = np.ones(N, bool)                                        # first entry of each pair
    np.not_equal(cols[1:], cols[:-1], out=first[1:])
    first[indptr[:-1][indptr[:-1] < N]] = True
    inv = np.empty(N, idx_t)
    inv[entry] = np.cumsum(first, dtype=idx_t) - 1
    del entry
    rows = np.repeat(np.arange(n, dtype=node_t), np.diff(indptr))[first]
    return rows, cols[first].astype(node_t, copy=False), inv


def assemble_blocks(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                    element: str = "c3d8i", chunk: int = CHUNK) -> BlockStiffness:
    """Global stiffness of the hexahedral mesh as summed 3x3 node blocks (no Python loop per element)."""
    n = nodes.shape[0]
    hexes = np.asarray(hexes, np.int64)
    ne = len(hexes)
    rows, cols, inv = node_pairs(hexes, n)
    blocks = np.zeros((9, rows.size))
    for s in range(0, ne, chunk):
        ke = hex8_stiffness_pairs(nodes[hexes[s:s + chunk]], E, nu, element)    # (m, 3, 3, 8, 8)
        m = ke.shape[0]
        kb = ke.reshape(m, 9, 64)
        sel = inv[64 * s:64 * (s + m)]
        lo, hi = int(sel.min()), int(sel.max()) + 1                 # pairs this batch touches
        loc = sel - lo
        for c in range(9):
            blocks[c, lo:hi] += np.bincount(loc, weights=kb[:, c].ravel(), minlength=hi - lo)
    del inv
    return BlockStiffness(n, rows, cols, blocks)


def assemble_stiffness(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                       element: str = "c3d8i", chunk: int = CHUNK) -> sp.csr_matrix:
    """Global stiffness (3n x 3n, CSR) of the hexahedral mesh [N/m]."""
    return assemble_blocks(nodes, hexes, E, nu, element, chunk).tocsr()
