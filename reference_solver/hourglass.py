"""Where reduced-integration elements (Hex20R, ``Element.hourglass = True``) may carry zero-energy modes.

Measured (tests/test_elements_interface.py, free stiffness, eigenvalues below 1e-9 of the largest): a
Hex20R element alone has 6 spurious modes, a one-element row (1 x 1 x n or 2 x 1 x 1) 3 to 4, while a
one-element-thick layer or wall (3 x 3 x 1, 3 x 1 x 3, 2 x 1 x 2) and a 2 x 2 x 2 block have none.
The rule that matches every one of those meshes: an element is at risk when it shares a face with another
element across fewer than two of its three pairs of opposite faces. A check of the mesh, not a proof;
the stiffness's null space (a small mesh) is the proof.
"""

from __future__ import annotations

import numpy as np


def _face_keys(cells: np.ndarray, local: tuple, n_corners: int) -> np.ndarray:
    """Sorted corner nodes (m, n_corners) of one local face of every element: a key shared by neighbours."""
    return np.sort(cells[:, list(local[:n_corners])], axis=1)


def hourglass_elements(blocks) -> np.ndarray:
    """Global indices (elements numbered block by block) of the elements whose type has ``hourglass`` set
    and that have face neighbours across fewer than two of their ``opposite_faces`` pairs."""
    keys, owners = [], []
    start = 0
    for b in blocks:
        for local, ftype in zip(b.element.faces, b.element.face_types):
            k = _face_keys(b.cells, local, ftype.n_corners)
            keys.append(np.pad(k, ((0, 0), (0, 4 - k.shape[1])), constant_values=-1))
        start += b.cells.shape[0]
    if not keys:
        return np.zeros(0, np.int64)
    _, inv, counts = np.unique(np.concatenate(keys), axis=0, return_inverse=True, return_counts=True)
    shared = counts[inv.ravel()] > 1
    out, start, pos = [], 0, 0
    for b in blocks:
        m, nf = b.cells.shape[0], len(b.element.faces)
        s = shared[pos:pos + m * nf].reshape(nf, m)
        if getattr(b.element, "hourglass", False):
            covered = sum(s[i] | s[j] for i, j in b.element.opposite_faces)
            out.append(start + np.flatnonzero(covered < 2))
        pos += m * nf
        start += m
    return np.concatenate(out) if out else np.zeros(0, np.int64)
