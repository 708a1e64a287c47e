"""Mixed element meshes (issue 23): a skirt meshed with the Gmsh API as an analyst does it -- the base annulus
quad-dominant (two quarters in triangles, two recombined) and extruded in recombined layers, so hexahedra and
wedges (prisms) stand on a base of quadrilateral and triangle faces -- written by ``gmsh.write`` as .msh, .inp and
.bdf, imported as one cell block per type and solved by the reference solver (tests/gmsh_skirt.py: gmsh_mixed).

48 x 6 x 1 (R 1.5, t 0.02, H 2 m), default loads without the stop, lambda = 0.3 (full contact), Lagrange
(face-weighted on 8-/6-node faces). Through-wall sigma_N per azimuth (-Sum force / Sum area of the row, the
project's quantity) against thin-ring beam theory N/(2 pi R t) + M cos(theta)/(pi R^2 t), largest error as a
fraction of the peak. Measured: hex8 + wedge6 0.0057 (the same generator all hexahedra: 0.0028); hex20 + wedge15
0.0162 on 48 around, 0.0055 on 96 (all hexahedra 0.0020 / 0.0012): the wedge quarters' rows converge; tet10 over a
wedge15 base layer 0.0167 / 0.0056.
Sum F = N and Sum sigma_N A = -N to ~1e-13. Gmsh's .msh of 15-node wedges is not read (meshio 5.3 has no
'wedge15' for Gmsh): refused in one line that names the .inp / .bdf.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from gmsh_skirt import gmsh_mixed

from deckbridge.errors import ModelError
from deckbridge.face_areas import contact_areas
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.quantities import beam_theory_sigma
from deckbridge.solve import build_problem, condense_model, solve_path

R, T = 1.5, 0.02


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    return gmsh_mixed(tmp_path_factory.mktemp("mixed1"), order=1, n_theta=48, n_z=6, n_r=1)


@pytest.fixture(scope="module")
def second(tmp_path_factory):
    return gmsh_mixed(tmp_path_factory.mktemp("mixed2"), order=2, n_theta=48, n_z=6, n_r=1)


def _model(files, fmt, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.file={files[fmt]}", f"mesh.sets={files['sets'][fmt]}", "contact.stop.side=none",
                           "steps.lambda_max=0.3", "steps.increments=1", "outputs.vtu=false", *extra])


def _solve_and_check(files, fmt, types, faces, tol):
    """Import, check the blocks and face types, solve at lambda 0.3 and check balance and beam theory."""
    m = _model(files, fmt)
    mesh = build_mesh(m)
    assert tuple(n for n, _ in mesh.cell_blocks) == types
    assert sorted(c.shape[0] for _, c in mesh.cell_blocks) == sorted(files["counts"].values())
    assert sorted(f.name for f, _ in mesh.table_faces) == sorted(faces)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh, system = condense_model(m, mesh)
        sol = solve_path(m, system, "lagrange")
    p = system.problem
    assert len(p.blocks) == 2 and p.n_elements == sum(files["counts"].values())
    tab = p.contact_surface == "table"
    assert sol.closed[-1][tab].all()
    s, f, lam, area = sol.sigma_n[-1][tab], sol.force[-1][tab], sol.load_factor[-1], mesh.table.area
    assert f.sum() == pytest.approx(m.loads.N, rel=1e-9)                       # Sum F = N
    assert -(s * area).sum() == pytest.approx(m.loads.N, rel=1e-9)             # Sum sigma_N A = -N
    th = mesh.table.theta_deg
    peak = abs(beam_theory_sigma(m.loads.N, lam * m.base_moment, R, T, 180.0))
    err = [abs((s[th == a] * area[th == a]).sum() / area[th == a].sum()
               - beam_theory_sigma(m.loads.N, lam * m.base_moment, R, T, a - m.loads.azimuth)) / peak
           for a in np.unique(th)]
    assert len(err) >= 48 and max(err) < tol, max(err)
    return mesh, p


@pytest.mark.parametrize("fmt", ["msh", "inp", "bdf"])
def test_first_order_hexahedra_and_wedges(first, fmt):
    mesh, p = _solve_and_check(first, fmt, ("c3d8i", "c3d6"), ["quad4", "tri3"], 0.0075)
    assert p.contact_weighting == "nodal" and not mesh.quadratic_faces


@pytest.mark.parametrize("fmt", ["inp", "bdf"])
def test_second_order_hexahedra_and_wedges(second, fmt):
    mesh, p = _solve_and_check(second, fmt, ("c3d20", "c3d15"), ["quad8", "tri6"], 0.02)
    assert p.contact_weighting == "face" and mesh.quadratic_faces


@pytest.mark.parametrize("fmt", ["inp", "bdf"])
def test_tetrahedra_over_a_wedge_layer(tmp_path_factory, fmt):
    """10-node tetrahedra over one layer of 15-node wedges at the base (a prism boundary layer), the two meeting
    on 6-node triangles. Measured 48 x 6 x 1: 0.0167 of the peak (96: 0.0056; the triangulated base's rows, as
    the wedge quarters of the hexahedral mixed mesh)."""
    files = gmsh_mixed(tmp_path_factory.getbasetemp() / f"tet_wedge_{fmt}", order=2, n_theta=48, n_z=6, n_r=1,
                       tet_layers=5)
    mesh, p = _solve_and_check(files, fmt, ("c3d15", "c3d10"), ["tri6"], 0.02)
    assert p.contact_weighting == "face"


def test_gmsh_msh_of_wedge15_refused_naming_the_other_formats(second):
    with pytest.raises(ModelError, match=r"mesh\.file = .*wedge15.*\.inp or \.bdf"):
        build_mesh(_model(second, "msh"))


@pytest.mark.parametrize("which, exact", [("first", "polygon"), ("second", "annulus")])
def test_contact_areas_on_mixed_faces(first, second, which, exact):
    """The table's areas on quad + triangle faces: per node the sum of each face type's own areas
    (face_areas.contact_areas), in total the base's area (first order: the polygonal annulus of 48 chords,
    exactly; second order: the true annulus within the curved edges' interpolation error)."""
    mesh = build_mesh(_model(first if which == "first" else second, "inp"))
    nodes, area = contact_areas(mesh.table_faces, mesh.nodes)
    assert np.array_equal(nodes, mesh.table.nodes) and np.array_equal(area, mesh.table.area) and (area > 0).all()
    per_type = np.zeros(mesh.n_nodes)
    for face in mesh.table_faces:
        n, a = contact_areas((face,), mesh.nodes)
        per_type[n] += a
    assert np.allclose(per_type[nodes], area, rtol=1e-13, atol=0)
    ro, ri, n = R + T / 2, R - T / 2, 48
    want = (n / 2 * np.sin(2 * np.pi / n) if exact == "polygon" else np.pi) * (ro ** 2 - ri ** 2)
    assert area.sum() == pytest.approx(want, rel=1e-12 if exact == "polygon" else 1e-5)


def test_first_and_second_order_together_refused(tmp_path):
    nodes = "\n".join(f"{i}, {1.5 + 0.01 * (i % 2)}, {0.01 * i}, {0.1 * (i // 8)}" for i in range(1, 24))
    path = tmp_path / "orders.inp"
    path.write_text(f"*NODE\n{nodes}\n*ELEMENT, TYPE=C3D8, ELSET=A\n1, 1, 2, 3, 4, 5, 6, 7, 8\n"
                    "*ELEMENT, TYPE=C3D15, ELSET=B\n2, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23\n"
                    "*NSET, NSET=BASE\n1\n*NSET, NSET=TOP\n5\n")
    with pytest.raises(ModelError) as err:
        build_mesh(load(None, [f"mesh.file={path}", "mesh.sets={base: BASE, top: TOP}"]))
    msg = str(err.value)
    assert msg.startswith("mesh.file = ") and "\n" not in msg
    assert "C3D8 (8-node)" in msg and "C3D15 (15-node)" in msg and "first- and second-order" in msg
    assert "node-based" in msg and "face-weighted" in msg


def test_hexahedra_with_tetrahedra_refused(tmp_path):
    nodes = "\n".join(f"{i}, {1.5 + 0.01 * (i % 2)}, {0.01 * i}, {0.1 * (i // 8)}" for i in range(1, 31))
    path = tmp_path / "hex_tet.inp"
    path.write_text(f"*NODE\n{nodes}\n*ELEMENT, TYPE=C3D20, ELSET=A\n1, " + ", ".join(map(str, range(1, 17)))
                    + ",\n" + ", ".join(map(str, range(17, 21))) + "\n*ELEMENT, TYPE=C3D10, ELSET=B\n2, "
                    + ", ".join(map(str, range(21, 31))) + "\n*NSET, NSET=BASE\n1\n*NSET, NSET=TOP\n5\n")
    with pytest.raises(ModelError, match=r"^mesh\.file = .*1 elements of type C3D20 \(hexahedra\) and 1 of type "
                                         r"C3D10 \(tetrahedra\): their faces do not conform"):
        build_mesh(load(None, [f"mesh.file={path}", "mesh.sets={base: BASE, top: TOP}"]))


def test_messages_name_the_file_and_its_types(tmp_path, second):
    """An imported quadratic mesh's refusals name mesh.file and the file's element types, never
    mesh.element = hex8i (the parametric skirt's key, left at its default by an import)."""
    from deckbridge.deck_elements import element_problem
    hex20 = gmsh_mixed(tmp_path / "hex20", order=2, n_theta=48, n_z=2, n_r=1, tri_quarters=())
    for files, types in ((hex20, "C3D20"), (second, "C3D20 + C3D15")):
        m = _model(files, "inp", "contact.stop.side=inner")
        mesh = build_mesh(m)
        for dialect in ("calculix", "abaqus", "nastran"):
            why = element_problem(dialect, m, mesh)
            assert why.startswith(f"mesh.file = skirt.inp ({types}): ") and "hex8i" not in why, why
        fric = _model(files, "inp", "contact.stop.side=inner", "contact.tangential=friction", "contact.friction=0.3")
        with pytest.raises(ModelError) as refused:          # friction with the stop: the one refusal left there
            build_problem(fric, build_mesh(fric))
        why = str(refused.value)
        assert why.startswith("contact.stop.side = 'inner': with contact.tangential = friction"), why
        assert why.endswith(f"(mesh.file=skirt.inp ({types}))") and "hex8i (" not in why, why


def test_outputs_and_decks_of_a_mixed_mesh(tmp_path, first):
    """solve writes its VTUs with one cell block per type (read back by meshio). The decks of a first-order mixed
    mesh without the stop -- Abaqus (Lagrange, augmented), CalculiX mortar, Nastran CGAP -- carry both types, read
    back by deckbridge's .inp reader and pyNastran: every skirt element once with its own type and nodes (one
    *ELEMENT and element set per type; CHEXA and CPENTA); MYSTRAN and nastran_surface are left out in one line
    naming the file's types, and with the radial stop every dialect is."""
    import meshio
    from pyNastran.bdf.bdf import read_bdf

    from deckbridge.deck_elements import element_problem
    from deckbridge.errors import DeckUnsupported
    from deckbridge.importers.inp_file import read_inp
    from deckbridge.numbering.skirt import mesh_node_ids
    from deckbridge.render import render_all
    from deckbridge.solve import solve_system, write_outputs
    m = _model(first, "inp", "outputs.vtu=true")
    mesh, system = condense_model(m)
    df, summary, sol = solve_system(m, mesh, system, "lagrange")
    write_outputs(tmp_path / "out", m, system, sol, df, summary, mesh)
    n_hex, n_wedge = first["counts"]["Hexahedron 8"], first["counts"]["Prism 6"]
    vtu = meshio.read(tmp_path / "out" / "result.vtu")
    assert {c.type: len(c.data) for c in vtu.cells} == {"hexahedron": n_hex, "wedge": n_wedge}
    assert all(len(v) == 2 for v in vtu.cell_data.values())
    notes = []
    render_all(m, tmp_path / "decks", mesh=mesh, on_unsupported=notes.append)
    assert len(notes) == 2 and all(isinstance(n, DeckUnsupported) for n in notes)
    assert all("mesh.file = skirt.inp (C3D8I + C3D6): " in str(n) for n in notes)
    want = {"C3D8I": {tuple(c) for c in mesh_node_ids(mesh, mesh.cell_blocks[0][1])},
            "C3D6": {tuple(c) for c in mesh_node_ids(mesh, mesh.cell_blocks[1][1])}}
    for deck in ("lagrange", "augmented", "ccx_lagrange"):
        raw = read_inp(tmp_path / "decks" / f"{m.name}_{deck}.inp")
        for t, cells in want.items():
            assert {tuple(c) for c in raw.elements[t][1]} == cells, (deck, t)
    bdf = read_bdf(str(tmp_path / "decks" / f"{m.name}_penalty.bdf"), xref=False, debug=None)
    assert {tuple(e.node_ids) for e in bdf.elements.values() if e.type == "CHEXA"} == want["C3D8I"]
    assert {tuple(e.node_ids) for e in bdf.elements.values() if e.type == "CPENTA"} == want["C3D6"]
    stop = _model(first, "inp", "contact.stop.side=inner")
    stop_mesh = build_mesh(stop)
    for dialect in ("calculix", "abaqus", "nastran"):
        assert "radial stop" in element_problem(dialect, stop, stop_mesh)


def test_run_with_ccx_on_hexahedra_and_wedges(tmp_path):
    """ccx accepts and solves a mixed C3D8I + C3D6 skirt (the mortar deck: one *ELEMENT and element set per type,
    slave faces S1 of either type) through the job (`run --with-ccx`), its table read and compared with the
    reference Lagrange through the wall (Sum F / Sum A per azimuth, the criterion of tests/scenario_checks.py:
    2 % of the state's peak). In full contact (lambda <= 0.6); measured 24 x 3 x 1: <= 0.48 % of the peak, ccx's
    Sum F = N to 4e-8. On 48 x 6 x 1 <= 0.35 % to lambda 0.6, 0.73 % at 0.7, but 4.4 / 9.3 % at 0.8 / 0.9 past
    liftoff (lift / R 1e-3 / 5e-3), where the same generator's all-hexahedra skirt agrees (peak -46.4 MPa both at
    0.8): the wedge quarters' past-liftoff gap is left open (issue 23). Both solvers lift the first node of the
    mixed skirt early and alike (lambda 0.4344 reference, 0.4350 ccx; all hexahedra 0.5882 / 0.5882)."""
    from unittest import mock

    from deckbridge.job import run_job
    from deckbridge.readers import read
    from scenario_checks import TOL_CCX, _through_wall
    files = gmsh_mixed(tmp_path / "mesh", order=1, n_theta=24, n_z=3, n_r=1)
    m = _model(files, "inp", "steps.lambda_max=0.6", "steps.increments=3")
    with mock.patch("deckbridge.job.write_report_with_verdict", return_value=[]):
        run_job(m, tmp_path / "run", with_ccx=True, echo=lambda *a, **k: None)
    deck = (tmp_path / "run" / "ccx" / f"{m.name}_ccx_lagrange.inp").read_text()
    assert "*ELEMENT, TYPE=C3D8I, ELSET=ESKIRT_C3D8I" in deck and "*ELEMENT, TYPE=C3D6, ELSET=ESKIRT_C3D6" in deck
    r = read(tmp_path / "run" / "reference_lagrange", model=m)
    c = read(tmp_path / "run" / "ccx", model=m)
    assert set(c.method) == {"mortar"}
    j = r[r.surface == "table"].merge(c[c.surface == "table"], on=["step", "increment", "node"], suffixes=("_r", "_c"))
    assert len(j) == (c.surface == "table").sum() and j.increment.nunique() >= 3
    worst = 0.0
    for _, g in j.groupby(["step", "increment"]):
        assert -np.sum(g.sigma_n_pa_c * g.area_m2_c) == pytest.approx(m.loads.N, rel=2e-3)   # ccx: Sum F = N
        d = _through_wall(g, "_r") - _through_wall(g, "_c")
        worst = max(worst, float(np.abs(d).max() / np.abs(g.sigma_n_pa_r).max()))
    assert worst <= TOL_CCX, worst


def test_memory_estimate_counts_every_block(first):
    """The guard's symbolic estimate analyses the node graph of every cell block (limits.symbolic_estimate): its
    factor holds more entries than the hexahedra's graph alone, and it counts every cell."""
    from reference_solver import estimate
    from deckbridge.limits import symbolic_estimate
    m = _model(first, "inp")
    mesh = build_mesh(m)
    p = build_problem(m, mesh)
    e = symbolic_estimate(m, mesh)
    hex_only = estimate.factor_entries([b.cells for b in p.blocks if b.cells.shape[1] == 8], p.n_nodes)
    nr = int(p.n_contacts + p.n_springs)
    assert e.factor_entries - nr * (nr + 1) // 2 > hex_only
    assert p.n_elements == sum(first["counts"].values())
