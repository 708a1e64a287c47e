"""Why quadratic faces need a face-weighted contact law (issue 23), in the reference solver itself.

A 1 m cube of 2 x 2 x 2 elements pressed by N = 1 MN onto a frictionless rigid base. On 8-node hexahedra,
with the load distributed by tributary areas, the exact field is uniform compression and node-based
Lagrange contact (today's law: a sign condition on each base node's force) carries it exactly. On Hex20R
and Tet10 it cannot: a uniform pressure needs -1/12 (quad8) or 0 (tri6) of the load at the face corners,
so under a rigid top (kinematic coupling) the corner nodes open while every mid-side node presses. The face matrix's projection of the same uniform load is exact (tests/test_elements_interface.py).
No deckbridge import.
"""

import numpy as np
import pytest

import reference_solver as rs
from element_meshes import block_mesh

N = 1.0e6


def _press(name, coupling="kinematic"):
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=2, L=(1.0, 1.0, 1.0))
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    top = np.flatnonzero(nodes[:, 2] > 1 - 1e-12)
    o = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    nb = base.size
    p = rs.Problem(nodes=nodes, hexes=cells, element=name, E=70e9, nu=0.3, contact_nodes=base,
                   contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=np.ones(nb),
                   contact_k=np.full(nb, 1e12), contact_clearance=np.zeros(nb), contact_surface=["table"] * nb,
                   spring_nodes=[o, o, far], spring_dirs=[[1, 0, 0], [0, 1, 0], [0, 1, 0]], spring_k=[1e6] * 3,
                   ref_point=[0.5, 0.5, 1.0], coupling_nodes=top, coupling_weights=_tributary(nodes[top]),
                   coupling=coupling, loads={"N": [0, 0, -N, 0, 0, 0], "T": [0] * 6})
    sol = rs.solve_path(rs.condense(p), "lagrange", base={"N": 1.0}, ramp={"T": 1.0}, increments=1)
    corner = np.isin(base, cells[:, :{"c3d8i": 8, "c3d20r": 8, "c3d10": 4}[name]].ravel())
    return nodes[base], sol.force[0], sol.closed[0], corner


def _tributary(xy):
    """Tributary area of a node of the 2 x 2 grid of 0.5 m cells on the unit square: 1/16, 1/8 or 1/4 m^2."""
    return 0.25 * np.prod(np.where(np.isclose(xy[:, :2] % 1.0, 0.0), 0.5, 1.0), axis=1)


def test_node_based_lagrange_is_exact_on_hex8():
    xy, f, closed, _ = _press("c3d8i", "distributing")
    assert closed.all()
    np.testing.assert_allclose(f, N * _tributary(xy), rtol=1e-9)


@pytest.mark.parametrize("name", ["c3d20r", "c3d10"])
def test_node_based_lagrange_opens_the_corners_of_quadratic_faces(name):
    _, f, closed, corner = _press(name)
    assert f.sum() == pytest.approx(N, rel=1e-9)
    assert not closed[corner].all()                     # corner nodes open under pure compression
    assert closed[~corner].all()                        # every mid-side node carries load
