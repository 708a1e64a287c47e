"""Skirt ids shared by every deck: node id = mesh node index + 1, element id = hexahedron index + 1."""

from __future__ import annotations

import numpy as np


def node_ids(index) -> np.ndarray:
    """Deck node ids of mesh node indices (0-based -> 1-based)."""
    return np.asarray(index, dtype=np.int64) + 1


def node_index(ids) -> np.ndarray:
    """Mesh node indices of deck node ids (inverse of :func:`node_ids`)."""
    return np.asarray(ids, dtype=np.int64) - 1


def element_ids(n_elements: int) -> np.ndarray:
    """Deck element ids of the skirt's ``n_elements`` hexahedra: 1..n."""
    return np.arange(1, n_elements + 1)


def max_node_id(mesh) -> int:
    """Largest skirt node id of ``mesh`` (= node count for the structured mesh)."""
    return int(mesh.n_nodes if getattr(mesh, "node_ids", None) is None else mesh.node_ids.max())


def max_elem_id(mesh) -> int:
    """Largest skirt element id of ``mesh`` (= hexahedron count for the structured mesh)."""
    return int(mesh.hexes.shape[0] if getattr(mesh, "elem_ids", None) is None else mesh.elem_ids.max())


def first_row_height(mesh) -> float:
    """Axial height of the first base element (edge 1-5 of the first table face's element) [m]."""
    e = mesh.hexes[mesh.base_elems[0]]
    return float(mesh.nodes[e[4], 2] - mesh.nodes[e[0], 2])


def elem_ids(mesh, index) -> np.ndarray:
    """Deck element ids of hexahedron indices of ``mesh``: its user ids, or index + 1."""
    index = np.asarray(index, dtype=np.int64)
    return index + 1 if getattr(mesh, "elem_ids", None) is None else np.asarray(mesh.elem_ids, np.int64)[index]


def mesh_node_ids(mesh, index) -> np.ndarray:
    """Deck node ids of node indices of ``mesh``: its user ids (imported mesh), or index + 1."""
    index = np.asarray(index, dtype=np.int64)
    return index + 1 if getattr(mesh, "node_ids", None) is None else np.asarray(mesh.node_ids, np.int64)[index]


def mesh_node_index(mesh, ids) -> np.ndarray:
    """Node indices of deck node ids of ``mesh`` (inverse of :func:`mesh_node_ids`)."""
    ids = np.asarray(ids, dtype=np.int64)
    if getattr(mesh, "node_ids", None) is None:
        return ids - 1
    order = np.argsort(mesh.node_ids)
    pos = np.searchsorted(mesh.node_ids, ids, sorter=order)
    return order[np.minimum(pos, order.size - 1)]


def bottom_row_index(mesh) -> np.ndarray:
    """Hexahedron indices of the bottom element row (face 1-2-3-4 on the base plane z = 0).

    Structured mesh: indices 0 .. n_r n_theta - 1 (element index = (k n_r + i) n_theta + j, k = 0);
    imported mesh (user ids): the hexahedra whose four base corners lie on z = 0 (1e-9 of the height); imported
    10-, 15-, 20-node cells (issue 23): those with a face on the table (``base_elems``).
    """
    if getattr(mesh, "elem_ids", None) is None:   # (tetrahedra, wedges: the cells of a coarse cell in a row)
        per_cell = mesh.hexes.shape[0] // (mesh.n_r * mesh.n_theta * mesh.n_z)
        return np.arange(mesh.n_r * mesh.n_theta * per_cell)
    if getattr(mesh, "table_faces", None) is not None:   # imported 10-/15-/20-node cells: not oriented
        return np.sort(np.asarray(mesh.base_elems, np.int64))
    z = mesh.nodes[mesh.hexes[:, :4], 2]
    return np.flatnonzero((np.abs(z) <= 1e-9 * np.ptp(mesh.nodes[:, 2])).all(axis=1))
