"""Geometric node-order check of quadratic solids (deckbridge/importers/node_order.py) on the skirt meshes
deckbridge builds (mid-side nodes on the true cylinder) and on the same meshes with one element's order broken."""

import warnings

import numpy as np
import pytest

from deckbridge.importers.node_order import midside_edges, node_order_problem
from deckbridge.mesh_order import skirt_cells
from deckbridge.model import load


def _cells(element):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=2", "mesh.n_r=1"])
    nodes, cells, _ = skirt_cells(m)
    return nodes, cells


def test_midside_edges_are_calculix_edges():
    assert midside_edges("c3d20")[:4] == [(8, 0, 1), (9, 1, 2), (10, 2, 3), (11, 0, 3)]
    assert midside_edges("c3d10") == [(4, 0, 1), (5, 1, 2), (6, 0, 2), (7, 0, 3), (8, 1, 3), (9, 2, 3)]
    assert midside_edges("c3d15")[6:] == [(12, 0, 3), (13, 1, 4), (14, 2, 5)]


@pytest.mark.parametrize("element", ["hex20", "tet10", "wedge15"])
def test_skirt_passes_and_broken_orders_are_named(element):
    nodes, cells = _cells(element)
    assert node_order_problem(nodes, cells, element) is None
    swapped = cells.copy()
    k = cells.shape[1]
    swapped[5, [k - 1, k - 2]] = swapped[5, [k - 2, k - 1]]           # two mid-side nodes exchanged
    assert node_order_problem(nodes, swapped, element).startswith("element 6 (C3D")
    inverted = cells.copy()
    order = list(range(k))
    inverted[7] = cells[7][midside_flip(element, order)]
    msg = node_order_problem(nodes, inverted, element)
    assert msg is not None and msg.startswith("element 8") and "Jacobian" in msg, msg


def midside_flip(element, order):
    """A node order that mirrors the element (two corners of the base swapped, mid-sides renumbered to
    stay on their edges): every mid-side node stays mid-edge, only the Jacobian's sign changes."""
    edges = midside_edges(element)
    swap = {"hex20": {0: 0, 1: 3, 2: 2, 3: 1, 4: 4, 5: 7, 6: 6, 7: 5},
            "tet10": {0: 0, 1: 2, 2: 1, 3: 3},
            "wedge15": {0: 0, 1: 2, 2: 1, 3: 3, 4: 5, 5: 4}}[element]
    new = list(order)
    for c, d in swap.items():
        new[c] = order[d]
    where = {frozenset((a, b)): m for m, a, b in edges}
    for m, a, b in edges:
        new[m] = order[where[frozenset((swap[a], swap[b]))]]
    return new


def test_gmsh_written_quadratic_skirt_is_in_calculix_order(tmp_path):
    """A second-order Gmsh skirt (Mesh.ElementOrder 2, SecondOrderIncomplete 1: 20-node hexahedra) as Gmsh
    writes it: .inp (C3D20) and .msh in CalculiX's order as read, .bdf (CHEXA) in Nastran's, which the
    import permutes (measured: read as it is, node 13 of every CHEXA is not mid-edge 5-6). Since issue 23 the
    import takes the type: the three files give the same C3D20 cells (the .bdf to its 8-character fields)."""
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).parent))
    from gmsh_skirt import gmsh_files
    from deckbridge.mesh import build_mesh
    f = gmsh_files(tmp_path, n_theta=16, n_z=2, order=2)
    cells = {}
    for fmt in ("inp", "msh", "bdf"):
        m = load(None, [f"mesh.file={f[fmt]}", f"mesh.sets={f['sets'][fmt]}"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mesh = build_mesh(m)
        assert mesh.element == "c3d20" and node_order_problem(mesh.nodes, mesh.hexes, "c3d20") is None
        cells[fmt] = mesh.nodes[mesh.hexes]
    np.testing.assert_allclose(cells["msh"], cells["inp"], atol=1e-12)
    np.testing.assert_allclose(cells["bdf"], cells["inp"], atol=1e-5)


def test_nastran_order_read_as_it_is_fails_the_check():
    from deckbridge.importers.node_order import NASTRAN_TO_CCX
    nodes, cells = _cells("hex20")
    inverse = np.argsort(NASTRAN_TO_CCX[20])
    as_nastran = cells[:, inverse]                                   # what a CHEXA card lists
    assert "node 13 is not near the mid-point of nodes 5 and 6" in node_order_problem(nodes, as_nastran, "hex20")
    nodes, cells = _cells("wedge15")
    assert node_order_problem(nodes, cells[:, np.argsort(NASTRAN_TO_CCX[15])], "wedge15") is not None
