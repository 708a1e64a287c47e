"""On the skirt's base (4-node faces) the lumped face matrix of reference_solver.face_weights is today's
tributary area: the contact area of every table row that deckbridge builds (quad_nodal_areas)."""

import numpy as np

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem
from reference_solver.face_weights import face_matrix, project_pressure, surface_faces


def test_lumped_face_matrix_is_the_tributary_area_of_the_table_rows():
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=2"])
    mesh = build_mesh(model)
    p = build_problem(model, mesh)
    z = p.nodes[:, 2]
    faces = surface_faces(p.blocks, z <= z.min() + 1e-12)
    surf, Ml = face_matrix(p.nodes, faces, lumped=True)
    table = p.contact_surface == "table"
    rows = p.contact_nodes[table]
    np.testing.assert_allclose(Ml.diagonal()[np.searchsorted(surf, rows)], p.contact_area[table], rtol=1e-12)
    assert np.array_equal(np.sort(rows), surf)
    # a uniform pressure's consistent loads project back to it, lumped or not
    _, M = face_matrix(p.nodes, faces)
    np.testing.assert_allclose(project_pressure(M, 2.5e6 * Ml.diagonal()), -2.5e6, rtol=1e-9)
