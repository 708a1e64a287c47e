"""The reference solver's element interface against independent truths (imports nothing from deckbridge).

Quadrature degrees against exact monomial integrals; shape functions (partition of unity, nodal delta);
exact volumes of distorted elements with planar faces (frustum formula, tetrahedron determinant); the
uniform-compression patch test on every type and the linear-pressure ("tilt") patch test on the quadratic
types and a mixed Hex20 + Wedge15 mesh (closed-form fields, 1e-10); zero-energy modes of Hex20R vs Hex20;
face-weighted shares, the L2 pressure projection and the lumped face matrix (docs/elements.md).
"""

from math import factorial

import numpy as np
import pytest
import scipy.sparse.linalg as spla

from element_meshes import block_mesh, grid, mixed_mesh
from reference_solver import fields, recover
from reference_solver.assembly import assemble_element_blocks
from reference_solver.element_faces import FACE_TYPES, QUAD4, QUAD8, TRI3, TRI6
from reference_solver.elements import ELEMENT_TYPES, element_type
from reference_solver.errors import ReferenceSolverError
from reference_solver.hourglass import hourglass_elements
from reference_solver.face_weights import face_matrix, face_shares, project_pressure, surface_faces
from reference_solver.kinematics import elasticity_matrix
from reference_solver.problem import ElementBlock, Problem
from reference_solver.quadrature import hex_rule, tet_rule, tri_rule, wedge_rule

E, NU = 70e9, 0.3
QUADRATIC = ("c3d20", "c3d20r", "c3d10", "c3d15")
L = (1.0, 0.8, 1.2)


def _simplex_monomial(e):
    """int over the unit simplex of prod x_i^e_i = prod e_i! / (d + sum e)!."""
    return np.prod([factorial(k) for k in e]) / factorial(len(e) + sum(e))


@pytest.mark.parametrize("rule, exact, degree", [
    (hex_rule(2), lambda e: np.prod([(1 - (-1) ** (k + 1)) / (k + 1) for k in e]), 3),
    (hex_rule(3), lambda e: np.prod([(1 - (-1) ** (k + 1)) / (k + 1) for k in e]), 5),
    (tri_rule(2), _simplex_monomial, 2), (tri_rule(4), _simplex_monomial, 4),
    (tet_rule(1), _simplex_monomial, 1), (tet_rule(2), _simplex_monomial, 2), (tet_rule(3), _simplex_monomial, 3),
    (wedge_rule(4, 3), lambda e: _simplex_monomial(e[:2]) * (1 - (-1) ** (e[2] + 1)) / (e[2] + 1), 4),
])
def test_quadrature_degree(rule, exact, degree):
    pts, w = rule
    d = pts.shape[1]
    for e in np.ndindex(*(degree + 1,) * d):
        if sum(e) <= degree:
            assert w @ np.prod(pts ** np.array(e), axis=1) == pytest.approx(exact(e), abs=1e-13), e


@pytest.mark.parametrize("name", list(ELEMENT_TYPES) + list(FACE_TYPES))
def test_shape_functions_partition_of_unity_and_nodal_delta(name):
    el = ELEMENT_TYPES.get(name) or FACE_TYPES[name]
    rng = np.random.default_rng(1)
    xi = rng.uniform(0, 0.5, (20, el.nodes.shape[1]))
    np.testing.assert_allclose(el.shape(xi).sum(axis=1), 1.0, atol=1e-13)
    np.testing.assert_allclose(el.dshape(xi).sum(axis=2), 0.0, atol=1e-12)
    np.testing.assert_allclose(el.shape(el.nodes), np.eye(el.nodes.shape[0]), atol=1e-12)


def _frustum(el, a=1.0, b=0.6, h=0.7, shift=(0.15, -0.1)):
    """Square (hex) or triangular (wedge) frustum with planar faces; exact volume h/3 (A1 + A2 + sqrt(A1 A2))."""
    if el.n_nodes in (8, 20):
        base = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
        area = lambda s: s * s  # noqa: E731
    else:
        base = np.array([[0, 0], [1, 0], [0, 1]], float)
        area = lambda s: s * s / 2  # noqa: E731
    bot = np.c_[a * base, np.zeros(len(base))]
    top = np.c_[b * base + shift, np.full(len(base), h)]
    corners = np.vstack([bot, top])
    nc = len(corners)
    mids = [(corners[i] + corners[j]) / 2 for m in el.nodes[nc:]
            for i in range(nc) for j in range(i + 1, nc) if np.allclose((el.nodes[i] + el.nodes[j]) / 2, m)]
    xyz = np.vstack([corners] + ([np.array(mids)] if mids else []))
    return xyz, h / 3 * (area(a) + area(b) + np.sqrt(area(a) * area(b)))


@pytest.mark.parametrize("name", ELEMENT_TYPES)
def test_exact_volume_of_a_distorted_element(name):
    el = element_type(name)
    if el.n_nodes in (4, 10):
        rng = np.random.default_rng(3)
        c = rng.uniform(-1, 1, (4, 3))
        if np.linalg.det(c[1:] - c[0]) < 0:
            c[[1, 2]] = c[[2, 1]]
        xyz = np.vstack([c] + [[(c[a] + c[b]) / 2 for a, b in ((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))]][:el.n_nodes > 4])
        want = np.linalg.det(c[1:] - c[0]) / 6
    else:
        xyz, want = _frustum(el)
    assert el.volume_weights(xyz[None]).sum() == pytest.approx(want, rel=1e-13)


def _patch(nodes, blocks, exact, eps_top):
    """Solve K u = 0 with u_z prescribed on base (0) and top (``eps_top`` x H at x), two in-plane pins from
    ``exact``; return the displacement (n, 3)."""
    K = assemble_element_blocks(nodes, blocks, E, NU).tocsr()
    z = nodes[:, 2]
    base, top = np.flatnonzero(z < 1e-12), np.flatnonzero(z > L[2] - 1e-12)
    origin = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    u = np.zeros(nodes.shape[0] * 3)
    fixed = np.concatenate([3 * base + 2, 3 * top + 2, [3 * origin, 3 * origin + 1, 3 * far + 1]])
    u[3 * top + 2] = eps_top(nodes[top, 0]) * L[2]
    ex = exact(nodes).ravel()
    for d in (3 * origin, 3 * origin + 1, 3 * far + 1):
        u[d] = ex[d]
    free = np.setdiff1d(np.arange(u.size), fixed)
    u[free] = spla.spsolve(K[free][:, free].tocsc(), -K[free][:, fixed] @ u[fixed])
    return u.reshape(-1, 3), K


def _tilt_exact(a, b):
    def u(x):
        X, Y, Z = x.T
        return np.c_[-NU * (a * X + b * X ** 2 / 2) - b * Z ** 2 / 2 + NU * b * Y ** 2 / 2,
                     -NU * (a + b * X) * Y, (a + b * X) * Z]
    return u


def _gauss_stress_error(nodes, blocks, u, a, b):
    """max |sigma - (0, 0, E (a + b x), 0, 0, 0)| at every Gauss point and at every node (extrapolated) [Pa]."""
    D = elasticity_matrix(E, NU)
    err = 0.0
    for name, cells in blocks:
        el = element_type(name)
        xyz = nodes[cells]
        s = np.einsum("egij,ej->egi", el.gauss_strain_operator(xyz, E, NU), u[cells].reshape(len(cells), -1)) @ D.T
        xg = np.einsum("ga,eak->egk", el.shape(el.points), xyz)
        want = np.zeros_like(s)
        want[..., 2] = E * (a + b * xg[..., 0])
        s_nodes = np.einsum("ag,egk->eak", el.extrapolation(), s)
        want_nodes = np.zeros_like(s_nodes)
        want_nodes[..., 2] = E * (a + b * xyz[..., 0])
        err = max(err, np.abs(s - want).max(), np.abs(s_nodes - want_nodes).max())
    return err


MESHES = {"parallelepipeds": dict(nx=2, ny=2, nz=2, shear=0.3, grade=True),
          "jiggled": dict(nx=2, ny=2, nz=3, jiggle=0.25)}


@pytest.mark.parametrize("mesh", MESHES)
@pytest.mark.parametrize("name", ELEMENT_TYPES)
def test_uniform_compression_patch_test(name, mesh):
    """Block on a frictionless base, top u_z = -eps H: sigma_zz = -E eps everywhere, all else 0 (1e-10)."""
    eps = -1e-3
    nodes, cells = block_mesh(name, L=L, **MESHES[mesh])
    u, _ = _patch(nodes, [(name, cells)], _tilt_exact(eps, 0.0), lambda x: eps + 0 * x)
    assert _gauss_stress_error(nodes, [(name, cells)], u, eps, 0.0) <= 1e-10 * E * abs(eps)


@pytest.mark.parametrize("name", QUADRATIC)
def test_tilt_patch_test_quadratic(name):
    """Top u_z = (a + b x) H, frictionless base: sigma_zz = E (a + b x), all else 0, on affine cells (1e-10).
    Tetrahedra are affine on any straight-edged mesh: the Tet10 mesh is also jiggled."""
    a, b = -1e-3, 4e-4
    kw = dict(nx=2, ny=2, nz=3, jiggle=0.25) if name == "c3d10" else MESHES["parallelepipeds"]
    nodes, cells = block_mesh(name, L=L, **kw)
    u, _ = _patch(nodes, [(name, cells)], _tilt_exact(a, b), lambda x: a + b * x)
    np.testing.assert_allclose(u, _tilt_exact(a, b)(nodes), atol=1e-10 * abs(a) * L[2])
    assert _gauss_stress_error(nodes, [(name, cells)], u, a, b) <= 1e-10 * E * abs(a)


def test_tilt_patch_fails_on_tet4_and_it_is_flagged():
    a, b = -1e-3, 4e-4
    nodes, cells = block_mesh("c3d4", L=L, **MESHES["parallelepipeds"])
    u, _ = _patch(nodes, [("c3d4", cells)], _tilt_exact(a, b), lambda x: a + b * x)
    assert _gauss_stress_error(nodes, [("c3d4", cells)], u, a, b) > 1e-2 * E * b * L[0]
    assert element_type("tet4").bending is False and all(element_type(n).bending for n in QUADRATIC)


@pytest.mark.parametrize("a, b", [(-1e-3, 0.0), (-1e-3, 4e-4)])
def test_mixed_hex20_wedge15_mesh_patch_tests(a, b):
    nodes, blocks = mixed_mesh(nx=4, ny=2, nz=2, L=L, shear=0.2)
    u, _ = _patch(nodes, blocks, _tilt_exact(a, b), lambda x: a + b * x)
    assert _gauss_stress_error(nodes, blocks, u, a, b) <= 1e-10 * E * abs(a)
    # the solver's own recovery over a two-block Problem: nodal sigma_zz = E (a + b x), cells' volume average
    p = Problem(nodes=nodes, hexes=None, blocks=tuple(ElementBlock(*bl) for bl in blocks), E=E, nu=NU,
                contact_nodes=[0], contact_normals=[[0, 0, 1]], contact_area=[1.0], contact_k=[1.0],
                contact_clearance=[0.0], contact_surface=["table"], spring_nodes=[], spring_dirs=np.zeros((0, 3)),
                spring_k=[], ref_point=[0, 0, 1.2], coupling_nodes=[1], coupling_weights=[1.0], loads={})
    st = recover.states_stress(p, u[None])[0]
    want = np.zeros((nodes.shape[0], 6))
    want[:, 2] = E * (a + b * nodes[:, 0])
    assert np.abs(st["nodal"] - want).max() <= 1e-10 * E * abs(a)
    assert st["cell"].shape == (p.n_elements, 6)
    centres = np.concatenate([np.einsum("a,eak->ek", element_type(n).shape(element_type(n).centre[None])[0],
                                        nodes[c]) for n, c in blocks])
    want_c = np.zeros((p.n_elements, 6))
    want_c[:, 2] = E * (a + b * centres[:, 0])
    assert np.abs(fields.element_stress(p, u) - want_c).max() <= 1e-10 * E * abs(a)


def _zero_modes(name, **kw):
    nodes, cells = block_mesh(name, **kw)
    K = assemble_element_blocks(nodes, [(name, cells)], E, NU).tocsr().toarray()
    w = np.linalg.eigvalsh(K)
    return int(np.sum(w < 1e-9 * w.max()))


@pytest.mark.parametrize("kw, n_r20", [(dict(nx=1, ny=1, nz=1), 12), (dict(nx=3, ny=1, nz=1), 10),
                                       (dict(nx=1, ny=1, nz=3), 10), (dict(nx=2, ny=1, nz=1), 9),
                                       (dict(nx=3, ny=3, nz=1), 6), (dict(nx=3, ny=1, nz=3), 6),
                                       (dict(nx=2, ny=1, nz=2), 6), (dict(nx=2, ny=2, nz=2), 6)])
def test_hex20r_zero_energy_modes_and_the_mesh_check(kw, n_r20):
    """Free stiffness (eigenvalues < 1e-9 of the largest): 6 rigid-body modes for Hex20 on any mesh;
    Hex20R has 6 hourglass modes in one element and 3-4 in one-element rows, none in a one-element layer
    or wall or a 2 x 2 x 2 block; :func:`hourglass.hourglass_elements` flags exactly the meshes with more."""
    assert _zero_modes("c3d20", **kw) == 6
    assert _zero_modes("c3d20r", **kw) == n_r20
    nodes, cells = block_mesh("c3d20r", **kw)
    assert (hourglass_elements([ElementBlock("c3d20r", cells)]).size > 0) == (n_r20 > 6)
    assert hourglass_elements([ElementBlock("c3d20", cells)]).size == 0


def test_unknown_element_is_the_solver_error():
    with pytest.raises(ReferenceSolverError, match="element = 'c3d27'"):
        element_type("c3d27")
    flat = np.zeros((1, 8, 3))
    with pytest.raises(ReferenceSolverError, match="non-positive Jacobian"):
        element_type("hex8").stiffness_pairs(flat, E, NU)


@pytest.mark.parametrize("face, corner, mid", [(QUAD8, -1 / 12, 1 / 3), (TRI6, 0.0, 1 / 3),
                                               (QUAD4, 1 / 4, None), (TRI3, 1 / 3, None)])
def test_uniform_pressure_shares(face, corner, mid):
    """int N_a dA / A on a distorted flat face with straight edges (affine for triangles, any quad shape)."""
    nc = face.n_corners
    c = np.array([[0, 0, 0], [2.0, 0.3, 0], [1.7, 1.5, 0], [-0.2, 1.1, 0]])[:nc]
    if nc == 4:
        c[2] = c[1] + c[3] - c[0]                 # parallelogram: the shares are then exactly these
    mids = [(c[i] + c[(i + 1) % nc]) / 2 for i in range(nc)] if face.n_nodes > nc else []
    xyz = np.vstack([c] + mids)[None]
    s = face_shares(face, xyz)[0]
    np.testing.assert_allclose(s[:nc] / s.sum(), corner, atol=1e-14)
    if mid is not None:
        np.testing.assert_allclose(s[nc:] / s.sum(), mid, atol=1e-14)


@pytest.mark.parametrize("name", list(ELEMENT_TYPES) + ["mixed"])
def test_projection_of_block_reactions_is_the_pressure(name):
    """Uniform compression: the base reactions projected by M^-1 give sigma_N = sigma_zz = -p at every base
    node (1e-10), though the nodal reactions of quadratic faces are -1/12 (quad8 corners) or 0 (tri6 corners)."""
    eps = -1e-3
    if name == "mixed":
        nodes, blocks = mixed_mesh(nx=4, ny=2, nz=2, L=L, shear=0.2)
    else:
        nodes, cells = block_mesh(name, L=L, nx=2, ny=2, nz=2, jiggle=0.25)
        blocks = [(name, cells)]
    u, K = _patch(nodes, blocks, _tilt_exact(eps, 0.0), lambda x: eps + 0 * x)
    r = (K @ u.ravel()).reshape(-1, 3)[:, 2]                  # force on the body from the base, > 0 pressing
    faces = surface_faces([ElementBlock(*b) for b in blocks], nodes[:, 2] < 1e-12)
    surf, M = face_matrix(nodes, faces)
    np.testing.assert_allclose(project_pressure(M, r[surf]), E * eps, rtol=0, atol=1e-10 * E * abs(eps))
    assert r[surf].sum() == pytest.approx(-E * eps * L[0] * L[1], rel=1e-10)


def test_lumped_quad4_matrix_is_the_tributary_area():
    """Row sums of M on a graded, sheared grid of 4-node faces = the quarter areas of the cells at each node."""
    nodes, hexes = grid(nx=3, ny=2, nz=1, L=L, shear=0.3, grade=True)
    faces = surface_faces([ElementBlock("c3d8i", hexes)], nodes[:, 2] < 1e-12)
    surf, Ml = face_matrix(nodes, faces, lumped=True)
    want = np.zeros(nodes.shape[0])
    for f in faces[0][1]:
        p = nodes[f]
        area = np.linalg.norm(np.cross(p[2] - p[0], p[3] - p[1])) / 2       # parallelogram
        want[f] += area / 4
    np.testing.assert_allclose(Ml.diagonal(), want[surf], rtol=1e-13)
    r = 3.0 * Ml.diagonal()
    np.testing.assert_allclose(project_pressure(Ml, r), -3.0, rtol=1e-13)


def test_a_throw_away_element_plugs_in_by_the_checklist():
    """ARCHITECTURE.md "Add an element", step 1 only: a class with its own quadrature (an 8-node hexahedron
    on 3 x 3 x 3 points), passed as an object (registration is step 2): assembly, recovery and the face
    matrix take it unchanged, and it passes the uniform-compression patch test."""
    from reference_solver.element_hex8 import Hex8

    class Hex8Gauss27(Hex8):
        name, aliases = "c3d8_27", ()
        points, weights = hex_rule(3)
        recovery = "1 x y z xy yz xz xyz"

        def extrapolation(self):
            return super(Hex8, self).extrapolation()

    el, eps = Hex8Gauss27(), -1e-3
    nodes, cells = block_mesh("c3d8", L=L, nx=2, ny=2, nz=2, jiggle=0.25)
    u, K = _patch(nodes, [(el, cells)], _tilt_exact(eps, 0.0), lambda x: eps + 0 * x)
    assert _gauss_stress_error(nodes, [(el, cells)], u, eps, 0.0) <= 1e-10 * E * abs(eps)
    r = (K @ u.ravel()).reshape(-1, 3)[:, 2]
    surf, M = face_matrix(nodes, surface_faces([ElementBlock(el, cells)], nodes[:, 2] < 1e-12))
    np.testing.assert_allclose(project_pressure(M, r[surf]), E * eps, atol=1e-10 * E * abs(eps))
