"""Mesh and contact data against closed-form geometry of a polygonal annulus."""

import numpy as np
import pytest

from deckbridge.mesh import build_mesh, quad_nodal_areas
from deckbridge.model import load


def _poly_annulus(n, ro, ri):
    """Area between two regular n-gons of circumradii ro > ri."""
    return 0.5 * n * np.sin(2 * np.pi / n) * (ro**2 - ri**2)


def test_counts_and_volumes():
    m = load(None, ["mesh.n_theta=24", "mesh.n_z=5", "mesh.n_r=2"])
    me = build_mesh(m)
    assert me.nodes.shape == (24 * 6 * 3, 3)
    assert me.hexes.shape == (24 * 5 * 2, 8)
    g = m.geometry
    from deckbridge.mesh import hex_volumes
    vol = hex_volumes(me.nodes[me.hexes]).sum()
    exact = _poly_annulus(24, g.radius + g.thickness / 2, g.radius - g.thickness / 2) * g.height
    assert vol == pytest.approx(exact, rel=1e-12)


def test_table_areas_and_penalty_follow_alpha_A2K_over_V():
    m = load(None, ["mesh.n_theta=32", "mesh.n_z=8", "mesh.n_r=2"])
    me = build_mesh(m)
    g = m.geometry
    a_exact = _poly_annulus(32, g.radius + g.thickness / 2, g.radius - g.thickness / 2)
    assert me.table.area.sum() == pytest.approx(a_exact, rel=1e-12)
    assert me.top_weights.sum() == pytest.approx(a_exact, rel=1e-12)
    # uniform prismatic elements: A^2 / V = A / h, so k_c = alpha K A_node / h per node
    h = g.height / 8
    kbulk = m.material.E / (3 * (1 - 2 * m.material.nu))
    np.testing.assert_allclose(me.table.k, 0.1 * kbulk * me.table.area / h, rtol=1e-12)
    # inner and outer face nodes have half the area of the mid-wall node row (n_r = 2)
    inner = me.table.r < g.radius - 1e-9
    mid = np.isclose(me.table.r, g.radius)
    assert me.table.area[inner].mean() == pytest.approx(0.5 * me.table.area[mid].mean(), rel=0.05)


def test_stop_slaves_are_the_face_nodes_with_radial_normals():
    m = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=2", "contact.stop.side=outer"])
    me = build_mesh(m)
    g = m.geometry
    assert me.stop.nodes.size == 16
    np.testing.assert_allclose(me.stop.r, g.radius + g.thickness / 2)
    radial = me.nodes[me.stop.nodes, :2] / me.stop.r[:, None]
    np.testing.assert_allclose(me.stop.normal[:, :2], -radial, atol=1e-12)  # outer stop pushes inwards
    # lower half of the first row of outer faces
    a = 0.5 * (g.height / 4) * 16 * 2 * (g.radius + g.thickness / 2) * np.sin(np.pi / 16)
    assert me.stop.area.sum() == pytest.approx(a, rel=1e-12)


def test_explicit_k_and_clearance():
    m = load(None, ["mesh.n_theta=16", "mesh.n_z=2", "contact.penalty.k_normal=1.0e+8",
                    "contact.stop.radius=1.48"])
    me = build_mesh(m)
    assert np.all(me.table.k == 1e8) and np.all(me.stop.k == 1e8)
    np.testing.assert_allclose(me.stop.clearance, 1.5 - 0.01 - 1.48, atol=1e-12)


def test_stop_penetrating_the_wall_is_refused():
    from deckbridge.model import ModelError
    with pytest.raises(ModelError, match="contact.stop.radius"):
        build_mesh(load(None, ["contact.stop.radius=1.495"]))


def test_quad_areas_of_a_unit_square():
    sq = np.array([[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]], float)
    np.testing.assert_allclose(quad_nodal_areas(sq), [[0.25] * 4])
