"""One penalty slope per quadratic face (issue 23): reference_solver.face_weights.face_slope, used by the reference's
face-integrated penalty (reference_solver/face_penalty.py) and by the CalculiX face-to-face deck
(deckbridge.deck_elements.quadratic_face_slopes), weighting k / A over a face with the hat basis' shares int Phi dA.

With an explicit contact.penalty.k_normal (one k [N/m] per node) k / A differs between corner and mid-side nodes of
8- and 6-node faces (their hat areas A/24 and 5A/24, A/12 and A/4), so the weighting matters. Truths:
- a block of hex20r / tet10 on a frictionless rigid base (nu = 0, rigid top) under a uniform pressure p with one k
  per base node: the table is as stiff as the model says, the penetration is p A / sum k (the sum of the nodal k,
  not an average of k / A) at every node, sigma_N = -p, and Sum sigma_N A = -N (1e-10);
- on hex20r and tet10 skirts the deck's and the reference's slopes give Sum_f K_f A_f = Sum k (1e-12);
- ccx face-to-face against the reference face penalty through the wall (hex20r and tet10 skirts, lambda 0.6).
"""

from __future__ import annotations

import shutil
import warnings

import numpy as np
import pytest

import reference_solver as rs
from element_meshes import block_mesh
from reference_solver.element_faces import QUAD8, TRI6
from reference_solver.elements import element_type
from reference_solver.face_weights import face_shares, face_slope, multiplier_shares, surface_faces

E, L, K_NODE = 70e9, (1.0, 0.8, 1.2), 4.0e9
needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")


def _base(nodes, cells, name):
    """Base rows (ascending), their hat areas [m^2] and the base faces [(face type, conn)]."""
    base = np.flatnonzero(nodes[:, 2] < 1e-12)
    on = np.zeros(nodes.shape[0], bool)
    on[base] = True
    faces = surface_faces([rs.ElementBlock(name, cells)], on)
    area = np.zeros(nodes.shape[0])
    for ftype, conn in faces:
        np.add.at(area, conn.ravel(), multiplier_shares(ftype, nodes[conn]).ravel())
    return base, area[base], faces


@pytest.mark.parametrize("face, corner, mid", [(QUAD8, 1 / 24, 5 / 24), (TRI6, 1 / 12, 1 / 4)])
def test_one_face_slope_is_the_sum_of_its_k_over_its_area(face, corner, mid):
    """A single flat face (its areas = its own hat shares): K = Sum k / A_face for any k, between the smallest and
    largest k / A; the consistent shares (negative / zero at corners) give another K (> 10 % off here)."""
    xyz = np.zeros((1, face.n_nodes, 3))
    xyz[0, :, :2] = face.nodes * (2.0, 1.0)
    a_face = 8.0 if face is QUAD8 else 1.0
    area = np.where(np.arange(face.n_nodes) < face.n_corners, corner, mid)[None] * a_face
    k = np.linspace(1.0, 3.0, face.n_nodes)[None] * 1e9
    K = face_slope(face, xyz, k, area)[0]
    assert K == pytest.approx(k.sum() / a_face, rel=1e-12)
    q = k / area
    assert q.min() <= K <= q.max()
    s = face_shares(face, xyz)
    consistent = float((s * q).sum() / s.sum())
    assert abs(consistent - K) > 0.1 * K                  # measured 10.4e9 vs 12e9 (tri6)


@pytest.mark.parametrize("name, n", [("c3d20r", 2), ("c3d10", 1)])
def test_block_with_one_k_per_node_penetrates_p_area_over_the_sum_of_k(name, n):
    """Block n x n x 2 (symmetric plan: every base face gets one K), uniform pressure p on a rigid top, nu = 0,
    k_c = 4e9 N/m on every base row (k / A 5x larger at quad8 corners than at mid-sides): every row penetrates
    p A / (n_rows k) and carries sigma_N = -p (1e-10), Sum sigma_N A = -p A = -N (1e-12), the solver's nodal
    stiffnesses add up to n_rows k."""
    nodes, cells = block_mesh(name, nx=n, ny=n, nz=2, L=L)
    base, area, faces = _base(nodes, cells, name)
    nb, H, A = base.size, L[2], L[0] * L[1]
    at = np.zeros(nodes.shape[0])
    at[base] = area
    slopes = np.concatenate([face_slope(ft, nodes[c], np.full(c.shape, K_NODE), at[c]) for ft, c in faces])
    np.testing.assert_allclose(slopes, slopes[0], rtol=1e-12)          # the symmetric plan: one K
    q = K_NODE / area
    assert q.max() > 2 * q.min()                                       # k / A is not uniform
    top = np.flatnonzero(nodes[:, 2] > H - 1e-12)
    o = base[np.argmin(np.linalg.norm(nodes[base], axis=1))]
    far = base[np.argmax(nodes[base, 0] - 10 * nodes[base, 1])]
    p = rs.Problem(nodes=nodes, hexes=cells, element=name, E=E, nu=0.0, contact_nodes=base,
                   contact_normals=np.tile([0, 0, 1.0], (nb, 1)), contact_area=area, contact_k=np.full(nb, K_NODE),
                   contact_clearance=np.zeros(nb), contact_surface=["table"] * nb,
                   spring_nodes=[o, o, far], spring_dirs=[[1, 0, 0], [0, 1, 0], [0, 1, 0]], spring_k=[1e6] * 3,
                   ref_point=[L[0] / 2, L[1] / 2, H], coupling_nodes=top, coupling_weights=np.ones(top.size),
                   coupling="kinematic", loads={"N": [0, 0, -1, 0, 0, 0], "T": [0] * 6}, contact_weighting="face")
    press = 3.0e6
    p.loads["N"] = [0, 0, -press * A, 0, 0, 0]
    sol = rs.solve_path(rs.condense(p), "penalty", base={"N": 1.0}, ramp={"T": 1.0}, increments=1)
    assert sol.closed[0].all()
    np.testing.assert_allclose(sol.gap[0], -press * A / (nb * K_NODE), rtol=1e-10, atol=0)
    np.testing.assert_allclose(sol.sigma_n[0], -press, rtol=1e-10, atol=0)
    assert float(sol.sigma_n[0] @ area) == pytest.approx(-press * A, rel=1e-12)
    assert float(sol.penalty_k.sum()) == pytest.approx(nb * K_NODE, rel=1e-12)


SKIRT = ["mesh.n_theta=48", "mesh.n_z=3", "mesh.n_r=1", "contact.stop.side=none", "contact.penalty.k_normal=1e8",
         "steps.lambda_max=0.6", "steps.increments=3", "outputs.vtu=false"]


def _skirt(element):
    from deckbridge.model import load
    from deckbridge.solve import condense_model
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")                 # the quadratic-mesh 'unverified' note
        model = load(None, [f"mesh.element={element}", *SKIRT])
        mesh, system = condense_model(model)
    return model, mesh, system


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_deck_and_reference_slopes_add_up_to_the_sum_of_k(element):
    """k_normal 1e8 N/m on a 48 x 3 x 1 skirt: the f2f deck's slope per base face and the reference face penalty's
    point weights (K |J| w) both give Sum_f K_f A_f = Sum k = n_rows k_normal (1e-12), and the rendered deck writes
    the deck's slopes (its groups hold every face)."""
    from deckbridge.deck_elements import base_faces, quadratic_face_slopes
    from deckbridge.dialects.calculix.render import f2f_context
    from reference_solver.face_penalty import FaceIntegration
    model, mesh, system = _skirt(element)
    tab = mesh.table
    assert np.all(tab.k == 1e8) and (tab.k / tab.area).max() > 2 * (tab.k / tab.area).min()
    faces = base_faces(mesh)
    K = quadratic_face_slopes(mesh, faces, tab.k)
    a_face = np.array([face_shares(element_type(mesh.element).face_types[f - 1], mesh.nodes[c][None]).sum()
                       for _, f, c in faces])
    assert float(K @ a_face) == pytest.approx(tab.k.sum(), rel=1e-12)
    p = system.problem
    on = p.contact_surface == "table"
    assert float(FaceIntegration(p).w.sum()) == pytest.approx(float(p.contact_k[on].sum()), rel=1e-12)
    assert float(p.contact_k[on].sum()) == pytest.approx(tab.k.sum(), rel=1e-12)
    ctx = f2f_context(model, mesh)
    written = [float(g["line"].split(",")[0]) for g in ctx["f2f_groups"]]
    assert sum(len(g["faces"].splitlines()) for g in ctx["f2f_groups"]) == len(faces)
    assert all(np.abs(w - K).min() <= 1e-6 * w for w in written)


def _table(df, step, lam):
    """Table rows of the one state at ``lam`` in ``step`` (one state per ccx time point: test_ccx_time_points)."""
    g = df[(df.surface == "table") & (df.step == step) & np.isclose(df.load_factor, lam)]
    assert g.increment.nunique() == 1
    return g


def _through_wall(g):
    """Sum sigma_N x area / Sum area per azimuth (deckbridge/quantities.py)."""
    a = g.assign(sa=g.sigma_n_pa * g.area_m2).groupby(np.round(g.theta_deg.to_numpy(float), 6))[["sa", "area_m2"]].sum()
    return a.sa / a.area_m2


@needs_ccx
@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_ccx_f2f_matches_the_reference_face_penalty_with_an_explicit_k(element, tmp_path):
    """k_normal 1e8 N/m, 48 x 3 x 1 skirt, no stop (ccx ~10 s one core; tet10: two slopes, 2 pairs): under N alone
    both penetrate N / Sum k (the ring's uniform pressure N / A over the slope Sum k / A; 1 %) and agree node by
    node within 0.5 % of it (measured 4e-4 hex20r, 1e-5 tet10); at lambda 0.6 ccx's forces carry N (1e-3:
    measured 4e-4 hex20r, 3e-6 tet10; the master ring's reaction, result_files.f2f_master_resultant: ccx prints no
    slave nodal force there), the reference's (1e-9), the through-wall sigma_N within 0.5 % of the peak
    (measured 0.25 % hex20r, 0.28 % tet10; 0.69 % on 24 x 3 x 1, also with the model's own penalty: the mesh,
    not the slope) and the penetrations within 1 % of the largest (measured 0.03 %, 0.01 %). tet10 with both
    pairs on one master surface (before render's pair_masters): 8 % off N, penetration 11 % over the reference.
    Through the wall sigma_N hardly depends on the slope at full contact: with the superseded weightings (deck
    with int N dA, reference with the modified basis) it still agreed within 0.23 % on hex20r, while the ccx
    penetration was 6.6 x the reference's (the deck's slope 2.05e10 against 1.27e11 Pa/m)."""
    from ccx_job import ccx_job
    from deckbridge.dialects.calculix.result_files import f2f_master_resultant
    from deckbridge.readers import read
    from deckbridge.solve import solve_system
    from reference_solver.face_penalty import face_weighted
    model, mesh, system = _skirt(element)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        job = ccx_job(model, tmp_path, "f2f")
        ccx = read(job.with_suffix(".frd"), fmt="calculix", model=model)
        ref = solve_system(model, mesh, face_weighted(system), "penalty", recover=False)[0]
    N, d0 = model.loads.N, model.loads.N / mesh.table.k.sum()
    r0, c0 = _table(ref, 1, 0.0).set_index("node"), _table(ccx, 1, 0.0).set_index("node")
    np.testing.assert_allclose(r0.gap_m, -d0, rtol=1e-2)
    assert np.abs(r0.gap_m - c0.gap_m.reindex(r0.index)).max() <= 5e-3 * d0
    r, c = _table(ref, 2, 0.6), _table(ccx, 2, 0.6)
    assert c.force_n.isna().all()           # 8-/6-node faces: ccx prints a pressure, no nodal force
    assert max(f2f_master_resultant(job).items())[1][0][2] == pytest.approx(N, rel=1e-3)     # the last state
    assert r.force_n.sum() == pytest.approx(N, rel=1e-9)
    peak = float(np.abs(r.sigma_n_pa).max())
    assert float(np.abs(_through_wall(r) - _through_wall(c)).max()) <= 5e-3 * peak
    gr, gc = r.set_index("node").gap_m, c.set_index("node").gap_m
    assert float(np.abs(gr - gc.reindex(gr.index)).max()) <= 1e-2 * float(np.abs(gr).max())


@needs_ccx
def test_ccx_f2f_pairs_of_different_slopes_do_not_share_master_faces(tmp_path):
    """hex8i 32 x 3 x 2, k_normal 1e8 N/m: the inner and outer base rows get slopes 1 % apart, so the f2f deck has
    two pairs; each has its own master faces (dialects/calculix/quadratic_master.pair_masters), and ccx then
    penetrates N / Sum k under N alone (1e-3; measured 1e-6) as the reference (1e-3), the table forces carry N.
    Both pairs on one master surface: 16.7 % more penetration (ccx 2.20)."""
    import re
    from ccx_job import ccx_job
    from deckbridge.model import load
    from deckbridge.readers import read
    from deckbridge.solve import condense_model, solve_system
    from reference_solver.face_penalty import face_weighted
    model = load(None, ["mesh.n_theta=32", "mesh.n_z=3", "mesh.n_r=2", "contact.stop.side=none",
                        "contact.penalty.k_normal=1e8", "steps.lambda_max=0.6", "steps.increments=3"])
    inp = ccx_job(model, tmp_path, "f2f")
    text = inp.read_text()
    pairs = re.findall(r"TYPE=SURFACE TO SURFACE\nSLAVE_TABLE\d+, (\w+)", text)
    assert len(pairs) == 2 and len(set(pairs)) == 2
    faces = [re.search(rf"\*SURFACE, NAME={m}\n((?:\d+, S\d\n)+)", text).group(1).splitlines() for m in pairs]
    assert not set(faces[0]) & set(faces[1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ccx = read(inp.with_suffix(".frd"), fmt="calculix", model=model)
        mesh, system = condense_model(model)
        ref = solve_system(model, mesh, face_weighted(system), "penalty", recover=False)[0]
    d0 = model.loads.N / mesh.table.k.sum()
    c0, r0 = _table(ccx, 1, 0.0), _table(ref, 1, 0.0)
    assert c0.force_n.sum() == pytest.approx(model.loads.N, rel=1e-6)
    np.testing.assert_allclose(c0.gap_m, -d0, rtol=1e-3)
    np.testing.assert_allclose(r0.gap_m, -d0, rtol=1e-3)
