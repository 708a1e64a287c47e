"""Global stiffness assembly: element matrices in batches, summed by 3x3 node blocks, then CSR.

Duplicates are summed on node pairs (64 per element instead of 576 scalar entries): the node-pair
keys are sorted once (np.unique), the 9 block components are summed with np.bincount, and the
block matrix (BSR, 3x3 blocks) is converted to CSR.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .elements import hex8_stiffness

CHUNK = 8192  # elements per batch of element matrices


def element_dofs(hexes: np.ndarray) -> np.ndarray:
    """Global dof numbers (ne, 24) of hexahedra: 3 * node + component."""
    return (3 * np.asarray(hexes, np.int64)[:, :, None] + np.arange(3)).reshape(len(hexes), 24)


def assemble_stiffness(nodes: np.ndarray, hexes: np.ndarray, E: float, nu: float,
                       element: str = "c3d8i", chunk: int = CHUNK) -> sp.csr_matrix:
    """Global stiffness (3n x 3n, CSR) of the hexahedral mesh [N/m]."""
    n = nodes.shape[0]
    hexes = np.asarray(hexes, np.int64)
    ne = len(hexes)
    key = (hexes[:, :, None] * n + hexes[:, None, :]).ravel()      # node pair (a, b) of every block
    uniq, inv = np.unique(key, return_inverse=True)
    blocks = np.zeros((9, uniq.size))
    for s in range(0, ne, chunk):
        ke = hex8_stiffness(nodes[hexes[s:s + chunk]], E, nu, element)          # (m, 24, 24)
        m = ke.shape[0]
        kb = ke.reshape(m, 8, 3, 8, 3).transpose(0, 1, 3, 2, 4).reshape(m * 64, 9)
        sel = inv[64 * s:64 * (s + m)]
        for c in range(9):
            blocks[c] += np.bincount(sel, weights=kb[:, c], minlength=uniq.size)
    rows, cols = np.divmod(uniq, n)
    indptr = np.searchsorted(rows, np.arange(n + 1))
    idx_t = np.int32 if 3 * n < 2**31 - 1 else np.int64
    K = sp.bsr_matrix((blocks.T.reshape(-1, 3, 3), cols.astype(idx_t), indptr.astype(idx_t)),
                      shape=(3 * n, 3 * n)).tocsr()
    return K
