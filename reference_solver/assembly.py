"""Global stiffness assembly: element matrices in batches, summed by 3x3 node blocks, then CSR.

Duplicates are summed on node pairs (64 per element instead of 576 scalar entries): the node-pair
keys are sorted once (np.unique), the 9 block components are summed with np.bincount over the
range of pairs a batch touches, giving the block form (node pairs sorted by row, then column).
``assemble_stiffness`` converts it to CSR; the condensation works on the blocks directly.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .elements import hex8_stiffness_pairs

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


def assemble_blocks(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                    element: str = "c3d8i", chunk: int = CHUNK) -> BlockStiffness:
    """Global stiffness of the hexahedral mesh as summed 3x3 node blocks (no Python loop per element)."""
    n = nodes.shape[0]
    hexes = np.asarray(hexes, np.int64)
    ne = len(hexes)
    key = (hexes[:, :, None] * n + hexes[:, None, :]).ravel()      # node pair (a, b) of every block
    uniq, inv = np.unique(key, return_inverse=True)
    del key
    idx_t = np.int32 if uniq.size < 2**31 - 1 else np.int64
    inv = inv.astype(idx_t, copy=False)
    blocks = np.zeros((9, uniq.size))
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
    node_t = np.int32 if n < 2**31 - 1 else np.int64
    rows, cols = np.divmod(uniq, n)
    del uniq
    return BlockStiffness(n, rows.astype(node_t), cols.astype(node_t), blocks)


def assemble_stiffness(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                       element: str = "c3d8i", chunk: int = CHUNK) -> sp.csr_matrix:
    """Global stiffness (3n x 3n, CSR) of the hexahedral mesh [N/m]."""
    return assemble_blocks(nodes, hexes, E, nu, element, chunk).tocsr()
