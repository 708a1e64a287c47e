"""CalculiX's dual mortar basis in the reference solver (issue 23; reference_solver/face_weights.py: dual_mortar,
face_law.py: contact_weighting 'face-dual').

ccx 2.20's TYPE=MORTAR interpolates the slave face with the transformed functions Nt = T N (a corner takes 1/5 of
each mid-side function of its edges) and its pressure with dual functions psi_j = sum_k A_jk Nt_k biorthogonal to
them (A = D M^-1, D = diag int Nt dA, M = int Nt Nt^T dA on the actual face); lambda_j >= 0 and the weighted gap
>= 0 node by node (docs/mortar_stop.md). The truths here: quadrature of the definitions on flat and curved faces
(biorthogonality, partition of unity), the closed form sigma_N = -p of a block in uniform compression with the
force balance, and ccx 2.20 itself on the same quadratic skirt (its multipliers rebuilt from its slave forces by
tests/mortar_columns.py: dual_multipliers, independently of the reference's law)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import reference_solver as rs
from element_meshes import block_mesh
from reference_solver.element_faces import QUAD8, TRI6
from reference_solver.face_weights import (DUAL_ALPHA, dual_coefficients, dual_mortar, face_shares,
                                           transformed_basis)
from reference_solver.quadrature import quad_rule

FLAT = {"quad8": np.array([[0, 0, 0], [2, 0.3, 0], [2.4, 1.5, 0], [0.2, 1.1, 0],
                           [1, 0.15, 0], [2.2, 0.9, 0], [1.3, 1.3, 0], [0.1, 0.55, 0]], float),
        "tri6": np.array([[0, 0, 0], [1.5, 0.2, 0], [0.4, 1.1, 0], [0.75, 0.1, 0], [0.95, 0.65, 0],
                          [0.2, 0.55, 0]], float)}
def _collapsed_rule(n):
    """n x n collapsed Gauss rule on the unit triangle (exact to degree 2n - 2: finer than the face's own)."""
    p, w = quad_rule(n)
    x = (1 + p[:, 0]) / 2
    return np.column_stack([x, (1 - x) * (1 + p[:, 1]) / 2]), w * (1 - x) / 4


FACES = {"quad8": (QUAD8, quad_rule(8)), "tri6": (TRI6, _collapsed_rule(8))}


def _curved(xyz, scale=0.25):
    """The face scaled by ``scale`` and wrapped onto a cylinder of radius 1.5 about the y axis, with a small bump
    along y (a skirt-wall-like doubly curved face: 0.6 m wide is a 23 deg arc)."""
    out = scale * xyz
    ang = out[:, 0] / 1.5
    out[:, 0], out[:, 2] = 1.5 * np.sin(ang), 1.5 * (1 - np.cos(ang)) + 0.1 * out[:, 1] ** 2
    return out


def _integrals(face, rule, xyz):
    """int psi_j Nt_k dA, int psi_j N_k dA, int sum_j psi_j Nt_k dA, int Nt_k dA with a finer rule than the face's."""
    pts, w = rule
    A, d = dual_coefficients(face, xyz[None])
    fine = dataclasses.replace(face, points=pts, weights=w)
    jw = (fine.area_jacobian(xyz[None]) * w)[0]
    N = face.shape(pts)
    Nt = N @ transformed_basis(face).T
    psi = Nt @ A[0].T                                                        # (p, k)
    return (np.einsum("p,pj,pk->jk", jw, psi, Nt), np.einsum("p,pj,pk->jk", jw, psi, N),
            jw @ (psi.sum(1)[:, None] * Nt), jw @ Nt, d[0])


@pytest.mark.parametrize("name", ["quad8", "tri6"])
@pytest.mark.parametrize("curved", [False, True])
def test_dual_functions_are_biorthogonal_to_the_transformed_ones(name, curved):
    """int psi_j Nt_k dA = delta_jk d_k with d_k = int Nt_k dA > 0, sum_j psi_j = 1, and the law's mortar matrix
    dual_mortar = int psi_j N_k dA, all by a finer quadrature (Gauss 8 x 8, collapsed 8 x 8 on the triangle) than
    the face's own (3 x 3, 6 points), to 1e-12 of the face area on the flat faces (the face's rule is exact there).
    On the curved ones (the Jacobian no polynomial) d to 1e-5 of the area (measured 9e-7 quad8), psi's
    coefficients A = D M^-1 carry the face rule's error in M: biorthogonality and int psi N to 2e-3 (measured
    5.3e-4 / 8.8e-4 quad8, 2.1e-4 / 3.6e-4 tri6; d 1.4e-7 tri6). The law needs d only (D = diag(d) T^-T)."""
    face, rule = FACES[name]
    xyz = _curved(FLAT[name]) if curved else FLAT[name]
    bio, mortar, unity, d_fine, d = _integrals(face, rule, xyz)
    area = d_fine.sum()
    tol, tol_d = ((2e-3, 1e-5) if curved else (1e-12, 1e-12))
    assert np.all(d > 0.02 * area)
    np.testing.assert_allclose(d_fine, d, rtol=0, atol=tol_d * area)
    np.testing.assert_allclose(unity, d, rtol=0, atol=tol_d * area)         # sum psi = 1: lambda = p exactly
    np.testing.assert_allclose(bio, np.diag(d), rtol=0, atol=tol * area)
    np.testing.assert_allclose(mortar, dual_mortar(face, xyz[None])[0], rtol=0, atol=tol * area)


@pytest.mark.parametrize("name, corner, mid", [("quad8", 1 / 20, 1 / 5), ("tri6", 2 / 15, 1 / 5)])
def test_one_fifth_gives_positive_weights_where_the_plain_functions_do_not(name, corner, mid):
    """On a regular face (square / right triangle) d = int Nt dA is A/20 at a quad8 corner and A/5 at a mid-side
    (tri6 2A/15, A/5) with ccx's alpha = 1/5 (DUAL_ALPHA); with alpha = 0 (Nt = N) the corner's is -A/12 (quad8) or
    0 (tri6): no dual basis with positive weights exists, hence ccx's transformation."""
    face, _ = FACES[name]
    nc = face.n_corners
    xyz = np.column_stack([face.nodes, np.zeros(face.n_nodes)])[None]       # natural coordinates as a flat face
    s = face_shares(face, xyz)[0]
    area = s.sum()
    d = transformed_basis(face) @ s
    assert DUAL_ALPHA == 0.2
    np.testing.assert_allclose(d[:nc], corner * area, rtol=1e-12)
    np.testing.assert_allclose(d[nc:], mid * area, rtol=1e-12)
    assert s[:nc].max() <= 1e-12 * area                                     # alpha = 0: the plain shares


def _block(name, load, method="lagrange"):
    """A graded, plan-sheared block (1 x 0.8 x 1.2 m, nu = 0) on a frictionless rigid base under a rigid top,
    solved with the dual-basis face-weighted Lagrange."""
    L = (1.0, 0.8, 1.2)
    nodes, cells = block_mesh(name, nx=2, ny=2, nz=2, L=L, shear=0.3, grade=True)
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    top = np.flatnonzero(nodes[:, 2] > L[2] - 1e-12)
    o = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    nb = base.size
    p = rs.Problem(nodes=nodes, hexes=cells, element=name, E=70e9, nu=0.0, contact_nodes=base,
                   contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=np.ones(nb),
                   contact_k=np.full(nb, 1e12), contact_clearance=np.zeros(nb), contact_surface=["table"] * nb,
                   spring_nodes=[o, o, far], spring_dirs=[[1, 0, 0], [0, 1, 0], [0, 1, 0]], spring_k=[1e6] * 3,
                   ref_point=[0.0, 0.0, L[2]], coupling_nodes=top, coupling_weights=np.ones(top.size),
                   coupling="kinematic", loads={"N": load, "T": [0] * 6}, contact_weighting="face-dual")
    return rs.solve_path(rs.condense(p), method, base={"N": 1.0}, ramp={"T": 1.0}, increments=1)


@pytest.mark.parametrize("name", ["c3d20", "c3d20r", "c3d10", "c3d15"])
def test_dual_basis_uniform_compression_gives_the_pressure_at_every_node(name):
    """sigma_N = -lambda = -p at every base node to 1e-10, every node closed (corners included), sum of the node
    forces = p A (the applied force) to 1e-12."""
    press, A = 2.0e6, 0.8
    Sx, Sy = A * (0.5 + 0.3 * 0.4), A * 0.4                                   # first moments of the sheared base
    sol = _block(name, [0, 0, -press * A, -press * Sy, press * Sx, 0])
    assert sol.closed[0].all()
    np.testing.assert_allclose(sol.sigma_n[0], -press, rtol=1e-10, atol=0)
    assert sol.force[0].sum() == pytest.approx(press * A, rel=1e-12)


def test_dual_basis_refuses_penalty():
    """'face-dual' is a basis of the face-weighted Lagrange law only (the face penalty keeps the hat basis)."""
    with pytest.raises(rs.ReferenceSolverError, match="only the lagrange method"):
        _block("c3d20", [0, 0, -1e6, 0, 0, 0], method="penalty")


# --- against ccx 2.20 TYPE=MORTAR on the same quadratic skirt ------------------------------------------------------
TOL = 0.02                      # of the peak |sigma_N| (issue 23)
SAME_LAW = 1e-3                 # one discretisation of one law on one model: measured <= 2.4e-4
COMPARED = (0.6, 0.8)           # past liftoff, inside the small-strain range (lift / (R + t/2) <= 0.01)
_RUNS: dict = {}


def dual_run(element: str, folder, same_model: bool) -> dict:
    """ccx's mortar deck and the reference's dual-basis Lagrange on one 24 x 3 x 1 ``element`` skirt (no stop, 5
    increments, default loads; built and read as tests/test_ccx_quadratic_mortar.py), once per module. ``same_model``:
    the top is loaded through a kinematic coupling (``load_introduction=kinematic``, in the deck and the reference)
    and the reference's circumferential springs are the deck's (``deck_elements.corner_spring_k``: the mid-side
    springs moved onto the corners); otherwise both as rendered / built. Per printed ccx state
    (:func:`mortar_columns.mortar_states` on the dual solution) plus the reference's multipliers ``lam_ref``
    (-sigma_N), ccx's ``lam_ccx`` (:func:`mortar_columns.dual_multipliers` of its slave forces) [Pa] and the
    reference's table force ``fz`` [N]."""
    if (element, same_model) in _RUNS:
        return _RUNS[element, same_model]
    from ccx_job import ccx_job
    from deckbridge.deck_elements import corner_spring_k
    from deckbridge.dialects.calculix.face_rows import TableProjection
    from deckbridge.numbering.skirt import mesh_node_ids
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.reference_dual import dual_system
    from deckbridge.solve import build_problem, solve_system
    from mortar_columns import TableColumns, dual_multipliers, mortar_states, state_index
    model = load(None, [f"mesh.element={element}", "mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=1",
                        "contact.stop.side=none", "steps.increments=5"]
                 + (["load_introduction=kinematic"] if same_model else []))
    inp = ccx_job(model, folder, "lagrange")
    mesh = build_mesh(model)
    p = build_problem(model, mesh)
    if same_model:
        p = dataclasses.replace(p, spring_k=corner_spring_k(mesh))
    system = dual_system(rs.condense(p))        # contact_weighting='face-dual', the table rows' areas its shares d
    _, _, sol = solve_system(model, mesh, system, "lagrange")
    cols = TableColumns(mesh, system)
    states = mortar_states(model, mesh, system, sol, inp)
    own = TableProjection(mesh, mesh_node_ids(mesh, cols.nodes), np.ones(cols.nodes.size, bool), basis="dual")
    for s in states:
        k = state_index(sol, 1 if s["lam"] == 0.0 else 2, s["lam"])
        s["lam_ref"] = -sol.sigma_n[k, cols.rows]
        s["lam_ccx"] = dual_multipliers(mesh, cols, s["rf"])
        s["read"] = -own.sigma(s["rf"])                  # the ccx reader's projection in ccx's own basis
        s["fz"] = float(sol.force[k, cols.rows].sum())
    _RUNS[element, same_model] = {"model": model, "states": states}
    return _RUNS[element, same_model]


def _differences(run) -> list[tuple[float, float, float]]:
    """(lambda, max |lambda_ref - lambda_ccx| node by node, max |d sigma_N| through the wall), both / the reference's
    peak multiplier, at every small-strain state; the table carries N on both sides."""
    n = run["model"].loads.N
    out = []
    for s in run["states"]:
        assert s["rz"] == pytest.approx(n, rel=1e-6) and s["fz"] == pytest.approx(n, rel=1e-9)
        # face_rows.TableProjection(basis='dual') (-D^-T r, D assembled from the faces) = ccx's lambda = T r / d
        np.testing.assert_allclose(s["read"], s["lam_ccx"], rtol=0, atol=1e-9 * np.abs(s["lam_ccx"]).max())
        if s["lift"] <= 0.01:
            peak = np.abs(s["lam_ref"]).max()
            out.append((s["lam"], float(np.abs(s["lam_ref"] - s["lam_ccx"]).max() / peak),
                        float(np.abs(s["ref"] - s["ccx"]).max() / peak)))
            assert s["lam"] not in COMPARED or not s["closed"], s["lam"]          # past liftoff there
    assert set(COMPARED) <= {lam for lam, *_ in out}, out
    return out


@pytest.mark.parametrize("element", ["hex20", "tet10"])
def test_dual_lagrange_is_ccx_mortar_on_the_same_model(tmp_path_factory, element):
    """One model on both sides (kinematic top; the deck's springs in the reference too): the reference's dual-basis
    multipliers equal ccx's node by node, and the through-wall sigma_N, within 0.1 % of the peak at every
    small-strain state (lambda 0 to 1, past liftoff from 0.6 on; measured node by node / through the wall at
    lambda 0.6: 0.0024 / 0.0006 % hex20, 0.0018 / 0.0009 % tet10; at 0.8: 0.0056 / 0.0016 %, 0.022 / 0.0043 %; at 1:
    0.024 / 0.002 %, 0.020 / 0.0035 %), so within the issue's 2 % at 0.6 and 0.8."""
    rows = _differences(dual_run(element, tmp_path_factory.mktemp(element), same_model=True))
    for lam, node, wall in rows:
        assert node <= SAME_LAW and wall <= SAME_LAW, (lam, node, wall)
        assert node <= TOL and wall <= TOL


@pytest.mark.parametrize("element", ["tet10", "hex20"])
def test_dual_lagrange_matches_ccx_mortar_as_rendered(tmp_path, element):
    """The model as rendered and built (distributing top: the reference's weights the consistent shares of the top
    faces, as ccx's *DISTRIBUTING, mesh_order.top_weights; springs on the mid-side nodes in the reference, on the
    corners in the deck): node by node and through the wall within 2 % of the peak at every small-strain state
    (lambda 0 to 0.8). Measured node by node / through the wall, % of the peak, lambda 0 / 0.2 / 0.4 / 0.6 / 0.8:
    hex20 0.0000 / 0.47 / 0.75 / 0.92 / 1.89 % and 0.0000 / 0.003 / 0.005 / 0.031 / 0.045 %; tet10 0.0000 / 0.51 /
    0.81 / 1.01 / 0.86 % and 0.0000 / 0.56 / 0.88 / 1.09 / 0.61 % (the rest is the springs, previous test). With
    the HRZ top weights before: hex20 4.73 % node by node at lambda 0, 5.43 % at 0.6 (a strict xfail), tet10 0.47 %
    at lambda 0, 1.31 % at 0.6 (docs/mortar_stop.md)."""
    rows = _differences(dual_run(element, tmp_path, same_model=False))
    for lam, node, wall in rows:
        assert node <= TOL and wall <= TOL, (lam, node, wall)
