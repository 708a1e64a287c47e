"""Geometric check of a solid's node order (issue 23): is a file's element in CalculiX's (and VTK's) order?

For 10-, 15- and 20-node solids (C3D10 / C3D15 / C3D20 order, ``reference_solver.element_quadratic``) every
mid-side node must lie near the mid-point of the two corner nodes of its edge, |x_m - (x_a + x_b)/2| <=
:data:`MIDSIDE_TOL` x |x_a - x_b| (a curved edge of a skirt meshed on the true cylinder is off by about
L / (8 R) of its length L), and the Jacobian must be positive at every Gauss point (corner order and
orientation). A mesher writing another order (a permuted edge list, an inverted element) is caught here.
"""

from __future__ import annotations

import numpy as np

from reference_solver.elements import element_type
from reference_solver.errors import ReferenceSolverError

MIDSIDE_TOL = 0.1
N_CORNERS = {4: 4, 6: 6, 8: 8, 10: 4, 15: 6, 20: 8}
# Nastran's mid-side order (CHEXA G9-G20: edges 1-2, 2-3, 3-4, 4-1, then the vertical 1-5 .. 4-8, then the
# top 5-6 .. 8-5; CPENTA G7-G15: 1-2, 2-3, 3-1, vertical 1-4 .. 3-6, top 4-5 .. 6-4) -> CalculiX's (top
# edges before the vertical ones): calculix[:, i] = nastran[:, NASTRAN_TO_CCX[k][i]]; CTETRA's is CalculiX's.
NASTRAN_TO_CCX = {20: list(range(12)) + [16, 17, 18, 19, 12, 13, 14, 15],
                  15: list(range(9)) + [12, 13, 14, 9, 10, 11]}


def to_calculix_order(etype: str, conn: np.ndarray) -> np.ndarray:
    """Connectivity (m, k) of a file's element type in CalculiX's node order (Nastran CHEXA / CPENTA with
    mid-side nodes are permuted, every other type is returned as it is)."""
    conn = np.asarray(conn)
    perm = NASTRAN_TO_CCX.get(conn.shape[1]) if etype.upper().startswith(("CHEXA", "CPENTA")) else None
    return conn if perm is None else conn[:, perm]


# a mirror of each element's corners (two corners swapped, or the hexahedron's 2-4 / 6-8): it turns an inverted
# element (every mid-side node mid-edge, the whole volume negative) into the same element, positive
MIRROR = {4: {0: 0, 1: 2, 2: 1, 3: 3}, 6: {0: 0, 1: 2, 2: 1, 3: 3, 4: 5, 5: 4},
          8: {0: 0, 1: 3, 2: 2, 3: 1, 4: 4, 5: 7, 6: 6, 7: 5}}


def mirror_order(element) -> np.ndarray:
    """The node order (k,) that mirrors an element type's corners, each mid-side node kept on its edge."""
    et = element_type(element)
    swap = MIRROR[N_CORNERS[et.n_nodes]]
    new = list(range(et.n_nodes))
    for c, d in swap.items():
        new[c] = d
    edges = midside_edges(et)
    where = {frozenset((a, b)): m for m, a, b in edges}
    for m, a, b in edges:
        new[m] = where[frozenset((swap[a], swap[b]))]
    return np.array(new)


def turn_inverted(nodes: np.ndarray, cells: np.ndarray, element) -> tuple[np.ndarray, int]:
    """(cells, count): the elements whose every integration point has a negative Jacobian (a mesher's
    inverted element: Gmsh's revolved tetrahedra) mirrored by :func:`mirror_order`, which is unambiguous;
    an element whose Jacobian changes sign is left to :func:`node_order_problem`."""
    et = element_type(element)
    cells = np.asarray(cells, np.int64)
    x = np.asarray(nodes, float)[cells]
    det = np.stack([np.linalg.det(np.einsum("ia,eaj->eij", et.dshape(np.asarray(xi, float)[None])[0], x))
                    for xi in et.points], axis=1)
    flip = (det < 0).all(axis=1)
    if flip.any():
        cells = cells.copy()
        cells[flip] = cells[flip][:, mirror_order(et)]
    return cells, int(flip.sum())


def midside_edges(element) -> list[tuple[int, int, int]]:
    """(mid-side node, corner a, corner b) of an element type, from its natural node coordinates."""
    et = element_type(element)
    nc = N_CORNERS[et.n_nodes]
    out = []
    for m in range(nc, et.n_nodes):
        pair = [(a, b) for a in range(nc) for b in range(a + 1, nc)
                if np.allclose((et.nodes[a] + et.nodes[b]) / 2, et.nodes[m])]
        out.append((m, *pair[0]))
    return out


def node_order_problem(nodes: np.ndarray, cells: np.ndarray, element, elem_ids=None) -> str | None:
    """One line naming the first element whose node order is not the element's (CalculiX's), or None.
    ``nodes`` (n, 3) [m], ``cells`` (m, k) node indices, ``elem_ids`` the file's ids (default index + 1)."""
    et = element_type(element)
    cells = np.asarray(cells, np.int64)
    ids = np.arange(1, len(cells) + 1) if elem_ids is None else np.asarray(elem_ids)
    x = np.asarray(nodes, float)[cells]
    for m, a, b in midside_edges(et):
        off = np.linalg.norm(x[:, m] - (x[:, a] + x[:, b]) / 2, axis=1)
        bad = np.flatnonzero(off > MIDSIDE_TOL * np.linalg.norm(x[:, a] - x[:, b], axis=1))
        if bad.size:
            return (f"element {int(ids[bad[0]])} ({et.name.upper()}): node {m + 1} is not near the mid-point of "
                    f"nodes {a + 1} and {b + 1} (not CalculiX's node order)")
    try:
        et.volume_weights(x)
    except ReferenceSolverError as err:
        k = int(str(err).split()[1])
        return f"element {int(ids[k])} ({et.name.upper()}): non-positive Jacobian (inverted, or corners out of order)"
    return None
