"""Peak memory of ``condense`` + ``solve_path`` estimated from the mesh before any work [bytes].

Model of the block path (trailing.py) with nb node pairs (<= 27 per node for hexahedra), N = 3 n
dofs, nr retained dofs and nL entries of the Cholesky factor:
- assembly: 4 int64 arrays of 64 per element (pair keys, their sort, permutation, inverse) + the
  9 x nb block components;
- split: the blocks, their pair indices and the lower triangle of P K P^T as coordinates and CSC
  (about 230 bytes per node pair in all);
- factorisation: the CSC triangle (54 bytes per pair) + the factor (8 bytes per entry, 1.1x for
  CHOLMOD's integer part and update workspace);
- dense condensation and contact: about ten nr x nr arrays alive at once.
The peak is the interpreter and mesh base plus the largest stage. ``factor_entries`` computes nL
from CHOLMOD's symbolic analysis of the node graph (9 entries per node-pair entry, an upper bound:
supernodes store their diagonal blocks in full); without it a shell fit nL = 26 N log2 N is used
(measured on the JAR skirt; a compact 3D solid fills faster, so pass ``factor_entries`` there).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import scipy.sparse as sp

BASE_BYTES = 250 * 2**20       # interpreter, NumPy/SciPy/CHOLMOD, deckbridge


def factor_entries(hexes, n_nodes: int) -> int | None:
    """Entries of the dof-level Cholesky factor from a symbolic analysis of the node graph, or None.

    ``hexes``: the connectivity (m, k) of any element type, or a list of them (the blocks of a mixed mesh).
    """
    from .linalg import _cholmod
    if _cholmod is None:
        return None
    from .assembly import node_pairs
    from .trailing import analyze_nodes, supernodal_size
    rows, cols, _ = node_pairs(hexes if isinstance(hexes, (list, tuple)) else np.asarray(hexes), n_nodes)
    G = sp.csc_matrix((np.ones(rows.size), (rows, cols)), shape=(n_nodes, n_nodes))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        f = analyze_nodes(G, mode="supernodal")                          # the condensation's own ordering
    n9 = supernodal_size(f, n_nodes)
    return None if n9 is None else 9 * n9                               # xsize of the node factor


def estimate_peak_bytes(n_nodes: int, n_hex: int, n_contact: int, n_spring: int = 0,
                        factor_entries: int | None = None, pairs_per_node: float = 27.0) -> int:
    """Estimated peak resident memory [bytes] of the whole load path (condensation, both methods)."""
    N = 3 * n_nodes
    nb = pairs_per_node * n_nodes
    nr = n_contact + n_spring
    nL = factor_entries if factor_entries is not None else 26.0 * N * math.log2(max(N, 2))
    base = BASE_BYTES + 200 * n_nodes + 130 * n_hex            # mesh, problem, dof maps, load vectors
    assembly = 4 * 8 * 64 * n_hex + 72 * nb
    split = 230 * nb
    factor = 54 * nb + 1.1 * 8 * nL
    dense = 1.1 * 8 * nL + 10 * 8 * nr * nr
    return int(base + max(assembly, split, factor, dense))
