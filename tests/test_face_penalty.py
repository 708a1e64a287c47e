"""The face-integrated penalty law (reference_solver/face_penalty.py, issues 23 and 24). No deckbridge import.

A block (graded, sheared in plan: affine cells) on a frictionless rigid base under a rigid top (kinematic
coupling, nu = 0), penalty slope K = k_c / A [Pa/m] uniform, every element type's base faces:
- uniform compression p: sigma_N = -p at every base node and the base penetrates p / K exactly (1e-10);
- tilt: sigma_zz = E (a + b x) with the penalty's linear penetration E (a + b x) / K is in the quadratic
  elements' space (u_x = -b (z^2 / 2 + E z / K)), so sigma_N = E (a + b x) node by node to 1e-10 of E |a|;
- the quadrature (28 / 56 / 7 / 28 points on quad4 / quad8 / tri3 / tri6, ccx's triangles) integrates
  polynomials of degree 5 exactly, and the kink of max(0, -g) converges to the exact integral.
"""

import numpy as np
import pytest

import reference_solver as rs
from element_meshes import block_mesh
from reference_solver.face_penalty import SUBTRIANGLES, FaceIntegration, face_points

E, L, K = 70e9, (1.0, 0.8, 1.2), 2.0e12
TYPES = ["c3d8", "c3d20", "c3d20r", "c3d10", "c3d15"]


def _lumped(nodes, cells, base, name):
    """Row sums of the base face matrix [m^2] (the tributary areas on 4-node faces)."""
    from reference_solver.face_weights import face_matrix, surface_faces
    on = np.zeros(nodes.shape[0], bool)
    on[base] = True
    surf, M = face_matrix(nodes, surface_faces([rs.ElementBlock(name, cells)], on), lumped=True)
    return M.diagonal()[np.searchsorted(surf, base)]


def _solve(name, load, k=K):
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=2, L=L, shear=0.3, grade=True)
    H = L[2]
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    top = np.flatnonzero(nodes[:, 2] > H - 1e-12)
    o = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    nb = base.size
    area = _lumped(nodes, cells, base, name) if name == "c3d8" else np.ones(nb)
    p = rs.Problem(nodes=nodes, hexes=cells, element=name, E=E, nu=0.0, contact_nodes=base,
                   contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=area, contact_k=k * area,
                   contact_clearance=np.zeros(nb), contact_surface=["table"] * nb,
                   spring_nodes=[o, o, far], spring_dirs=[[1, 0, 0], [0, 1, 0], [0, 1, 0]], spring_k=[1e6] * 3,
                   ref_point=[0.0, 0.0, H], coupling_nodes=top, coupling_weights=np.ones(top.size),
                   coupling="kinematic", loads={"N": load, "T": [0] * 6}, contact_weighting="face")
    sol = rs.solve_path(rs.condense(p), "penalty", base={"N": 1.0}, ramp={"T": 1.0}, increments=1)
    return p, nodes, base, sol


def _area_moments():
    A = L[0] * L[1]                                   # parallelogram x += 0.3 y
    Sx, Sy = A * (L[0] / 2 + 0.3 * L[1] / 2), A * L[1] / 2
    Ixx = L[1] * L[0] ** 3 / 3 + L[0] * (0.3 * L[1]) ** 2 * L[1] / 3 + L[0] ** 2 * 0.3 * L[1] ** 2 / 2
    Ixy = L[0] ** 2 * L[1] ** 2 / 4 + 0.3 * L[0] * L[1] ** 3 / 3
    return A, Sx, Sy, Ixx, Ixy


@pytest.mark.parametrize("name", TYPES)
def test_uniform_compression_gives_the_pressure_and_the_penalty_penetration(name):
    press = 2.0e6
    A, Sx, Sy, _, _ = _area_moments()
    p, nodes, base, sol = _solve(name, [0, 0, -press * A, -press * Sy, press * Sx, 0])
    assert sol.closed[0].all()
    np.testing.assert_allclose(sol.sigma_n[0], -press, rtol=1e-10, atol=0)
    np.testing.assert_allclose(sol.gap[0], -press / K, rtol=1e-10, atol=0)
    assert sol.force[0].sum() == pytest.approx(press * A, rel=1e-12)
    np.testing.assert_allclose(sol.penalty_k, FaceIntegration(p).nodal_k(), rtol=1e-12)
    if name == "c3d8":                                # 4-node faces: k_c of each node under a uniform penetration
        np.testing.assert_allclose(sol.penalty_k, p.contact_k, rtol=1e-12)


@pytest.mark.parametrize("name", ["c3d20", "c3d20r", "c3d10", "c3d15"])
def test_tilt_gives_the_linear_pressure(name):
    a, b = -1.0e-4, -0.5e-4
    A, Sx, Sy, Ixx, Ixy = _area_moments()
    Fz, My, Mx = E * (a * A + b * Sx), -E * (a * Sx + b * Ixx), E * (a * Sy + b * Ixy)
    p, nodes, base, sol = _solve(name, [0, 0, Fz, Mx, My, 0])
    assert sol.closed[0].all()
    np.testing.assert_allclose(sol.sigma_n[0], E * (a + b * nodes[base, 0]), rtol=0, atol=1e-10 * E * abs(a))
    np.testing.assert_allclose(sol.gap[0], E * (a + b * nodes[base, 0]) / K, rtol=0, atol=1e-10 * E * abs(a) / K)


@pytest.mark.parametrize("face", sorted(SUBTRIANGLES))
def test_face_points_integrate_degree_5_and_the_kink(face):
    """Monomials s^i t^j, i + j <= 5, on the reference face (exact integrals), and int max(0, -(s - c)) over the
    square / triangle: the sub-triangle rule converges to it as the faces get finer (ccx's scheme)."""
    pts, w = face_points(face)
    n = {"quad4": 28, "quad8": 56, "tri3": 7, "tri6": 28}[face]
    assert pts.shape == (n, 2)
    quad = face.startswith("quad")
    from math import factorial
    for i in range(6):
        for j in range(6 - i):
            if quad:
                exact = (1 - (-1) ** (i + 1)) / (i + 1) * (1 - (-1) ** (j + 1)) / (j + 1)
            else:
                exact = factorial(i) * factorial(j) / factorial(i + j + 2)
            assert w @ (pts[:, 0] ** i * pts[:, 1] ** j) == pytest.approx(exact, abs=1e-14)
    kink = w @ np.maximum(0.0, 0.3 - pts[:, 0])                      # one face across the contact edge
    exact = (1.3 ** 2 / 2) * 2 if quad else (0.3 ** 2 / 2 - 0.3 ** 3 / 6)
    assert abs(kink - exact) <= 0.05 * exact                         # the rule is not exact on the kink
