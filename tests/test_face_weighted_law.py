"""The face-weighted (mortar-type) Lagrange law (reference_solver/face_law.py, issue 23). No deckbridge import.

A block (graded, sheared in plan: affine cells) on a frictionless rigid base under a rigid top (kinematic
coupling, nu = 0 so the exact fields below keep the top plane and rigid):
- uniform compression: sigma_N = -p at every base node (1e-10) and every base node closed, corners included,
  for 8-, 20-, 10- and 15-node elements (the nodal law opens the corners of 8-/6-node faces:
  tests/test_quadratic_node_contact.py);
- tilt: sigma_zz = E (a + b x) is in the quadratic elements' space, so sigma_N = E (a + b x) at every base
  node to 1e-10 of E |a|;
- 4-node faces with the row-sum lumped M (the tributary areas) reproduce the nodal law to 1e-9.
sigma_N = -T^-1 r (r the nodal forces of the solution, T the law's weighting matrix: the L2 projection).
"""

import numpy as np
import pytest
import scipy.sparse.linalg as spla

import reference_solver as rs
from element_meshes import block_mesh
from reference_solver.face_law import weighting_matrix

E, L = 70e9, (1.0, 0.8, 1.2)
QUADRATIC = ["c3d20", "c3d20r", "c3d10", "c3d15"]
CORNERS = {"c3d8": 8, "c3d20": 8, "c3d20r": 8, "c3d10": 4, "c3d15": 6}


def _problem(name, load, weighting="face", nu=0.0, area=None, **mesh):
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=2, L=L, shear=0.3, grade=True, **mesh)
    H = L[2]
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    top = np.flatnonzero(nodes[:, 2] > H - 1e-12)
    o = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    nb = base.size
    p = rs.Problem(nodes=nodes, hexes=cells, element=name, E=E, nu=nu, contact_nodes=base,
                   contact_normals=np.tile([0, 0, 1.0], (nb, 1)),
                   contact_area=np.ones(nb) if area is None else area(nodes, cells, base),
                   contact_k=np.full(nb, 1e12), contact_clearance=np.zeros(nb), contact_surface=["table"] * nb,
                   spring_nodes=[o, o, far], spring_dirs=[[1, 0, 0], [0, 1, 0], [0, 1, 0]], spring_k=[1e6] * 3,
                   ref_point=[0.0, 0.0, H], coupling_nodes=top, coupling_weights=np.ones(top.size),
                   coupling="kinematic", loads={"N": load, "T": [0] * 6}, contact_weighting=weighting)
    sol = rs.solve_path(rs.condense(p), "lagrange", base={"N": 1.0}, ramp={"T": 1.0}, increments=1)
    return p, nodes, base, cells, sol


def _sigma_n(p, force):
    """-D^-T r [Pa]: the law's pressure field at the contact rows."""
    return -spla.spsolve(weighting_matrix(p).T.tocsc(), force)


def _base_area_moment():
    """Area and first moment int x dA of the sheared base [m^2, m^3] (parallelogram x += 0.3 y)."""
    A = L[0] * L[1]
    return A, A * (L[0] / 2 + 0.3 * L[1] / 2)


@pytest.mark.parametrize("name", QUADRATIC + ["c3d8"])
def test_uniform_compression_gives_the_pressure_at_every_base_node(name):
    press = 2.0e6
    A, _ = _base_area_moment()
    # force at the ref point (on the top, at x = y = 0): a pure pressure needs the moment of -press A at the centroid
    _, Sx = _base_area_moment()
    Sy = A * L[1] / 2
    load = [0, 0, -press * A, -press * Sy, press * Sx, 0]
    p, nodes, base, cells, sol = _problem(name, load)
    assert sol.closed[0].all()                                       # corners included
    np.testing.assert_allclose(_sigma_n(p, sol.force[0]), -press, rtol=1e-10, atol=0)
    np.testing.assert_allclose(sol.sigma_n[0], -press, rtol=1e-10, atol=0)      # what the solver reports
    assert sol.force[0].sum() == pytest.approx(press * A, rel=1e-12)
    corner = np.isin(base, cells[:, :CORNERS[name]].ravel())
    if name != "c3d8":
        assert np.any(sol.force[0][corner] <= 0)                     # the consistent shares: <= 0 at corners


@pytest.mark.parametrize("name", QUADRATIC)
def test_tilt_patch_test_gives_the_linear_pressure(name):
    a, b = -1.0e-4, -0.5e-4                                          # sigma_zz = E (a + b x) < 0 on the base
    A, Sx = _base_area_moment()
    Sy = A * L[1] / 2
    Ixx = (L[1] * L[0] ** 3 / 3 + L[0] * (0.3 * L[1]) ** 2 * L[1] / 3 + L[0] ** 2 * 0.3 * L[1] ** 2 / 2)
    Ixy = L[0] ** 2 * L[1] ** 2 / 4 + 0.3 * L[0] * L[1] ** 3 / 3    # int x y dA on the parallelogram
    Fz = E * (a * A + b * Sx)                                        # top traction t_z = sigma_zz
    My = -E * (a * Sx + b * Ixx)                                     # M = r x F about (0, 0, H)
    Mx = E * (a * Sy + b * Ixy)
    p, nodes, base, cells, sol = _problem(name, [0, 0, Fz, Mx, My, 0])
    assert sol.closed[0].all()
    expect = E * (a + b * nodes[base, 0])
    np.testing.assert_allclose(_sigma_n(p, sol.force[0]), expect, rtol=0, atol=1e-10 * E * abs(a))


def _tributary(nodes, cells, base):
    """Row sums of the base's face matrix (4-node faces: the tributary areas) [m^2]."""
    from reference_solver.face_weights import face_matrix, surface_faces
    from reference_solver.elements import element_type
    on = np.zeros(nodes.shape[0], bool)
    on[base] = True
    surf, M = face_matrix(nodes, surface_faces([rs.ElementBlock("c3d8", cells)], on), lumped=True)
    assert np.array_equal(surf, np.sort(base)) and element_type("c3d8").n_nodes == 8
    return M.diagonal()[np.searchsorted(surf, base)]


def test_lumped_face_law_on_4_node_faces_is_the_nodal_law():
    load = [0, 0, -3.0e6, -1.2e6, 2.7e6, 0]          # resultant at x = 0.9, y = 0.4: off the kern, some nodes open
    runs = {w: _problem("c3d8", load, w, nu=0.3, area=_tributary) for w in ("nodal", "face-lumped")}
    (_, _, _, _, nodal), (_, _, _, _, lumped) = runs["nodal"], runs["face-lumped"]
    assert 0 < nodal.closed[0].sum() < nodal.closed[0].size
    np.testing.assert_array_equal(lumped.closed[0], nodal.closed[0])
    np.testing.assert_allclose(lumped.force[0], nodal.force[0], rtol=0, atol=1e-9 * np.abs(nodal.force[0]).max())


def test_face_lumped_weighting_refuses_penalty():
    """('face' with penalty is the face-integrated penalty law: tests/test_face_penalty.py)"""
    A, Sx = _base_area_moment()
    pr, *_ = _problem("c3d8", [0, 0, -1e6 * A, -1e6 * A * L[1] / 2, 1e6 * Sx, 0], "face-lumped")
    with pytest.raises(rs.ReferenceSolverError, match="only the lagrange method"):
        rs.solve_path(rs.condense(pr), "penalty", base={"N": 1.0}, ramp={"T": 1.0}, increments=1)
