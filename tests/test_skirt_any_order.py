"""The parametric skirt in every element type (issue 23, deckbridge/mesh_order.py): geometry against the exact
annulus, conformity of the split cells, positive slave areas, the solve on linear faces against beam theory
and the face-weighted law chosen on quadratic faces."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from deckbridge.errors import ModelError
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.solve import build_problem, solve_model
from reference_solver.elements import element_type
from reference_solver.face_weights import face_shares

TYPES = ("hex8i", "hex8", "hex20", "hex20r", "tet10", "wedge15", "tet4")
SMALL = ["mesh.n_theta=24", "mesh.n_z=3", "mesh.n_r=2"]


def _model(element, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.element={element}", *SMALL, *extra])


def _boundary_area(mesh) -> float:
    """Area [m^2] of the faces that belong to one cell only (a crack between cells would add to it)."""
    et = element_type(mesh.element)
    seen: dict = {}
    for local, ftype in zip(et.faces, et.face_types):
        conn = mesh.hexes[:, list(local)]
        for key, row in zip(map(tuple, np.sort(conn, axis=1)), conn):
            seen.setdefault(key, []).append((ftype, row))
    area = 0.0
    for rows in seen.values():
        assert len(rows) <= 2, "a face shared by more than two cells"
        if len(rows) == 1:
            ftype, row = rows[0]
            area += face_shares(ftype, mesh.nodes[row][None]).sum()
    return area


@pytest.mark.parametrize("element", TYPES)
@pytest.mark.parametrize("cone", [False, True])
def test_volume_and_surface_of_the_exact_annulus(element, cone):
    """Volume and bounding surface of the mesh against the exact wall (cylinder, or cone frustum): quadratic
    types put their mid-side nodes on the true surface, so their error is far below the 8-node chords'."""
    m = _model(element, *(["geometry.top_radius=1.2"] if cone else []))
    mesh = build_mesh(m)
    g = m.geometry
    et = element_type(mesh.element)
    vol = et.volume_weights(mesh.nodes[mesh.hexes]).sum()
    r0, r1, t, H = g.radius, g.r_top, g.thickness, g.height
    exact_vol = 2 * math.pi * t * H * (r0 + r1) / 2
    slant = math.hypot(H, r1 - r0)
    exact_area = 2 * math.pi * (r0 + r1) * slant + 2 * math.pi * t * (r0 + r1)   # two lateral faces + two rings
    # 24 chords of x = 15 deg: polygon / circle = sin(x) / x, 1.14e-2 short; quadratic arcs: below 2e-5
    tol = 1.2e-2 if et.n_nodes in (4, 8) else 2e-5
    assert vol == pytest.approx(exact_vol, rel=tol)
    assert _boundary_area(mesh) == pytest.approx(exact_area, rel=tol)


@pytest.mark.parametrize("element", TYPES[2:])
def test_slave_areas_positive_and_summing_to_the_base(element):
    m = _model(element)
    mesh = build_mesh(m)
    g, ms = m.geometry, m.mesh
    assert mesh.element == element_type(element).name
    assert np.all(mesh.table.area > 0) and np.all(mesh.table.k > 0)
    # the distributing top's weights: HRZ areas on tet4's 3-node faces, on 8-/6-node ones ccx's consistent shares
    # int N dA (mesh_order.top_weights: <= 0 at quad8 corners, about 0 at tri6 ones; only their sum must be > 0)
    assert np.all(mesh.top_weights > 0) == (element == "tet4")
    ring = 2 * math.pi * g.radius * g.thickness
    tol = 1.2e-2 if element == "tet4" else 2e-5          # chords (see above) or quadratic arcs
    assert mesh.table.area.sum() == pytest.approx(ring, rel=tol)
    assert mesh.top_weights.sum() == pytest.approx(ring, rel=tol)
    r_in = g.radius - g.thickness / 2
    assert mesh.stop.area.sum() == pytest.approx(2 * math.pi * r_in * g.height / ms.n_z / 2, rel=1e-12)  # line weights
    assert np.allclose(np.hypot(*mesh.nodes[mesh.stop.nodes, :2].T), r_in, rtol=1e-12)
    assert mesh.quadratic_faces == (element != "tet4")


def test_tet4_and_hex8_number_their_nodes_as_the_eight_node_mesh():
    base = build_mesh(_model("hex8i"))
    for element in ("tet4", "hex8"):
        mesh = build_mesh(_model(element))
        assert np.array_equal(mesh.nodes, base.nodes)
        assert np.array_equal(mesh.table.nodes, base.table.nodes)


@pytest.mark.parametrize("element", ["hex8", "tet4"])
def test_solve_on_linear_faces_against_beam_theory(element):
    """Step 1 (N alone, full contact): through-wall sigma_N = -N / (2 pi R t) around the ring."""
    m = _model(element, "steps.lambda_max=0.3", "steps.increments=1", "outputs.vtu=false")
    df, summary = solve_model(m, "lagrange")
    d = df[(df.surface == "table") & (df.step == 1)]
    wall = -d.groupby(d.theta_deg.round(6))["force_n"].sum() / d.groupby(d.theta_deg.round(6))["area_m2"].sum()
    exact = -m.loads.N / (2 * math.pi * m.geometry.radius * m.geometry.thickness)
    assert np.abs(wall.to_numpy() / exact - 1).max() < 0.02
    assert summary["reaction_force_n"]["1"][2] == pytest.approx(m.loads.N, rel=1e-9)


@pytest.mark.parametrize("element", ["hex20", "hex20r", "tet10", "wedge15"])
def test_quadratic_faces_get_the_face_weighted_law(element):
    """The refusal is lifted for frictionless contact (face_law.py; tests/test_face_weighted_skirt.py)."""
    assert build_problem(_model(element)).contact_weighting == "face"
    assert build_problem(_model("hex8i")).contact_weighting == "nodal"


def test_bad_and_warned_values():
    with pytest.raises(ModelError, match=r"^mesh.element = 'hex27': must be one of hex8i, hex8"):
        load(None, ["mesh.element=hex27"])
    with pytest.warns(UserWarning, match="tet4.*bending patch test"):
        load(None, ["mesh.element=tet4"])
    with pytest.raises(ModelError, match=r"^mesh.element = 'hex20'.*mesh.file"):
        load(None, ["mesh.element=hex20", "mesh.file=x.inp", "mesh.sets={base: B, top: T}"])
    with pytest.raises(ModelError, match=r"^contact.pads"):
        build_mesh(_model("hex20r", "contact.pads={count: 4, width_deg: 30, first_deg: 0}"))


def test_hex20r_warns_where_hourglass_modes_are_possible():
    """One element along z and through the wall: every element has face neighbours around only (a row),
    where C3D20R has zero-energy modes beyond the 6 rigid-body ones (counted on the free stiffness of a thick
    ring, t = 0.3 m, H = 1 m: measured 7, C3D20 6; on the thin default wall the slender elements' bending
    modes also fall below 1e-9 of the largest eigenvalue); a wall one element thick but two high has just the
    6, and no warning."""
    from reference_solver.assembly import assemble_stiffness
    THICK = ["geometry.thickness=0.3", "geometry.height=1.0"]

    def zero_modes(mesh):
        K = assemble_stiffness(mesh.nodes, mesh.hexes, 2.1e11, 0.3, "c3d20r").toarray()
        w = np.linalg.eigvalsh(K)
        return int((w < 1e-9 * w.max()).sum())

    with pytest.warns(UserWarning, match=r"hex20r: 8 of 8 elements .*hourglass"):
        row = build_mesh(load(None, ["mesh.element=hex20r", "mesh.n_theta=8", "mesh.n_z=1", "mesh.n_r=1", *THICK]))
    assert zero_modes(row) == 7
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        wall = build_mesh(load(None, ["mesh.element=hex20r", "mesh.n_theta=8", "mesh.n_z=2", "mesh.n_r=1", *THICK]))
    assert zero_modes(wall) == 6


@pytest.mark.parametrize("element", ["tet4", "hex8"])
def test_run_wall_areas_sum_to_the_base_section(tmp_path, element):
    """The run's wall_stress.csv: area per azimuth sums to the base annulus (chords: 1.2e-2), and
    Sum sigma_zz x area = N in step 1 (the wall's axial resultant; distributing top, 24 x 3 x 2)."""
    import pandas as pd

    from deckbridge.job import run_job
    m = _model(element, "steps.increments=1")
    run_job(m, tmp_path, echo=lambda s: None)
    w = pd.read_csv(tmp_path / "reference_lagrange" / "wall_stress.csv")
    s1 = w[w.step == 1]
    g = m.geometry
    assert s1.area_m2.sum() == pytest.approx(2 * math.pi * g.radius * g.thickness, rel=1.2e-2)
    assert -(s1.szz_mean_pa * s1.area_m2).sum() == pytest.approx(m.loads.N, rel=1e-9)   # measured 1e-12
