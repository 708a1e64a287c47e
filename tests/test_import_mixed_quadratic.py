"""Decks of second-order mixed meshes (issue 23): a Gmsh-built skirt of 20-node hexahedra and 15-node wedges
(tests/gmsh_skirt.py: gmsh_mixed, order 2; two quarters of the base annulus in triangles, so the table faces are
quad8 and tri6), and 10-node tetrahedra over a 15-node wedge layer.

Truths: CalculiX run on the decks against the reference solver on the same mesh, through the wall (-Sum F / Sum A
per azimuth, the project's quantity, tests/scenario_checks.py), within 2 % of the state's peak at every state of
the small-strain range (lift / (R + t/2) <= 0.01), in full contact and past liftoff: ccx mortar against the
reference in ccx's own multiplier basis (``reference/mortar``, deckbridge/reference_dual.py) and ccx face-to-face
against the reference's face-integrated penalty (``reference/f2f``, deckbridge/reference_f2f.py); the force balance
(Sum F = N); the slope rule of the face-to-face deck (Sum over faces of K A = Sum k_c); pyNastran and deckbridge's
.inp reader reading the Simcenter and Abaqus decks back cell by cell. A kinematic top on both sides: with the
distributing one the decks' consistent top shares and the reference's HRZ areas differ on tall quadratic cells
(note4.md, another helper's work), which is not what is compared here.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from gmsh_skirt import gmsh_mixed

from deckbridge.model import load

TOL = 0.02                      # of the reference's peak |sigma_N| (issue 23)
SMALL_STRAIN = 0.01             # lift / (R + t/2)


def _model(files, *extra):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load(None, [f"mesh.file={files['inp']}", f"mesh.sets={files['sets']['inp']}", "contact.stop.side=none",
                           "load_introduction=kinematic", "outputs.vtu=false", *extra])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    return gmsh_mixed(tmp_path_factory.mktemp("mixed_quadratic"), order=2, n_theta=48, n_z=3, n_r=1)


@pytest.fixture(scope="module")
def solved(files, tmp_path_factory):
    """One ccx run per deck (mortar, face-to-face) and the reference partners of both, on 48 x 3 x 1."""
    import shutil

    from deckbridge.dialects import DIALECTS
    from deckbridge.mesh import build_mesh
    from deckbridge.readers import read
    from deckbridge.reference_dual import mortar_series
    from deckbridge.reference_f2f import f2f_series
    from deckbridge.render import render_all
    from deckbridge.solve import condense_model
    folder = tmp_path_factory.mktemp("mixed_quadratic_run")
    m = _model(files, "steps.lambda_max=0.7", "steps.increments=2")
    mesh = build_mesh(m)
    render_all(m, folder / "decks", mesh=mesh, names=["calculix"])
    out = {"model": m, "mesh": mesh, "decks": folder / "decks"}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh, system = condense_model(m, mesh)
        ref = {"mortar": mortar_series(m, mesh, system, "ref").table, "f2f": f2f_series(m, mesh, system, "ref").table}
    for deck, method in (("lagrange", "mortar"), ("f2f", "f2f")):
        inp = folder / deck / f"{m.name}_ccx_{deck}.inp"
        inp.parent.mkdir()
        shutil.copyfile(folder / "decks" / inp.name, inp)
        DIALECTS["calculix"].run(inp, timeout_s=300)
        out[method] = (ref[method], read(inp.parent, model=m))
    return out


def _states(run, method):
    """(load factor, lift / (R + t/2) of the reference, every reference table row closed, the joined table rows)
    per state of step 2 both have."""
    from scenario_checks import _through_wall
    m = run["model"]
    r, c = run[method]
    r, c = r[r.surface == "table"], c[c.surface == "table"]
    j = r.merge(c, on=["step", "increment", "node"], suffixes=("_r", "_c"))
    assert np.allclose(j.load_factor_r, j.load_factor_c)
    out = []
    for (step, _), g in j.groupby(["step", "increment"]):
        lift = max(float(g.gap_m_r.max()), 0.0) / (m.geometry.radius + m.geometry.thickness / 2)
        d = _through_wall(g, "_r") - _through_wall(g, "_c")
        out.append((float(g.load_factor_r.iloc[0]), step, lift, bool((g.status_r == "closed").all()),
                    float(np.abs(d).max() / np.abs(g.sigma_n_pa_r).max()), g))
    return out


@pytest.mark.parametrize("method", ["mortar", "f2f"])
def test_ccx_against_the_reference_in_full_contact_and_past_liftoff(solved, method):
    """ccx on the mixed decks against the reference through the wall, % of the state's peak, at lambda 0, 0.35 (full
    contact) and 0.7 (past liftoff, lift / R 2e-5 .. 1.4e-4). Measured (48 x 3 x 1, 72 C3D20 + 144 C3D15, kinematic
    top): mortar 0.46 / 0.64 / 0.91 %, face-to-face 0.014 / 0.090 / 1.63 %.
    Where the differences come from: the C3D15 cells (ccx's 15-node wedge against the reference's): on the same
    generator's all-C3D20 skirt the mortar pair agrees to 0.000-0.014 % (lambda 0-0.8), and on the parametric
    wedge15 skirt (24 x 3 x 1, one model on both sides, tests/test_dual_mortar.py's set-up) ccx and the reference
    differ by 0.27 % through the wall already under N alone (hex20 / tet10: <= 0.0006 %); largest at the tri6
    faces' mid-side nodes on the inner and outer edge (3 % of their force). Further past liftoff the face-to-face
    pair parts at the contact edge on either mesh: 2.61 % mixed, 2.60 % all C3D20 at lambda 0.8 (lift / R 4e-4;
    mortar 1.88 % mixed, 0.014 % all C3D20). The same file with its C3D20 renamed C3D20R (not run here): mortar
    0.89 / 1.23 / 1.67 %, face-to-face 0.014 / 0.088 / 1.60 %; C3D10 over a C3D15 base layer (gmsh_mixed tet_layers
    2, 48 x 3 x 1): mortar 0.14 / 0.19 / 0.88 %, face-to-face 0.011 / 0.099 / 1.27 %."""
    states = _states(solved, method)
    small = [s for s in states if s[2] <= SMALL_STRAIN]
    assert any(s[3] for s in small) and any(not s[3] for s in small), [(s[0], s[2], s[3]) for s in states]
    worst = max(s[4] for s in small)
    assert worst <= TOL, [(s[0], s[3], round(100 * s[4], 3)) for s in small]


@pytest.mark.parametrize("method", ["mortar", "f2f"])
def test_ccx_tables_carry_n(solved, method):
    """Sum F = N at every state: ccx's table read back (-Sum sigma_N x area)."""
    n = solved["model"].loads.N
    for lam, _, _, _, _, g in _states(solved, method):
        assert -np.sum(g.sigma_n_pa_c * g.area_m2_c) == pytest.approx(n, rel=2e-3), lam


def _node_sets(blocks) -> dict:
    """Node ids of every *NSET of a deck (``keyword_blocks``), GENERATE or listed."""
    out = {}
    for k, o, d in blocks:
        if k == "NSET":
            ids = [int(x) for line in d for x in line.split(",") if x.strip()]
            if "GENERATE" in o:
                ids = list(range(ids[0], ids[1] + 1, ids[2] if len(ids) > 2 else 1))
            out.setdefault(o["NSET"].upper(), set()).update(ids)
    return out


def test_decks_carry_both_types_with_springs_on_corners_and_no_slave_spc(solved):
    """The CalculiX decks of C3D20 + C3D15: one *ELEMENT and element set per type, every skirt cell once with its own
    nodes (deckbridge's .inp reader); the table's slave faces are every base face of either type (quad8 and tri6) and
    no *BOUNDARY holds a slave node; the mortar deck's circumferential springs sit on corner nodes only and carry
    the model's total stiffness (deck_elements.corner_spring_k)."""
    from deckbridge.importers.inp_file import read_inp
    from deckbridge.importers.inp_mesh import keyword_blocks
    from deckbridge.numbering.skirt import mesh_node_ids
    m, mesh = solved["model"], solved["mesh"]
    want = {"C3D20": mesh.blocks[0][1], "C3D15": mesh.blocks[1][1]}
    n_faces = {f.name: c.shape[0] for f, c in mesh.table_faces}
    assert n_faces == {"quad8": 24, "tri6": 48}
    table = set(mesh_node_ids(mesh, mesh.table.nodes).tolist())
    corners = np.concatenate([c[:, :f.n_corners].ravel() for f, c in mesh.table_faces])
    corners = set(mesh_node_ids(mesh, corners).tolist())
    for deck in ("lagrange", "f2f"):
        path = solved["decks"] / f"{m.name}_ccx_{deck}.inp"
        raw = read_inp(path)
        for t, cells in want.items():
            assert {tuple(c) for c in raw.elements[t][1]} == {tuple(c) for c in mesh_node_ids(mesh, cells)}, (deck, t)
        blocks = keyword_blocks(path.read_text())
        slave = [d for k, o, d in blocks if k == "SURFACE" and o["NAME"].startswith("SLAVE_TABLE")]
        assert sum(len(d) for d in slave) == sum(n_faces.values()), deck
        sets = _node_sets(blocks)
        fixed = set()
        for k, _, d in blocks:
            for line in d if k == "BOUNDARY" else ():
                first = line.split(",")[0].strip()
                fixed |= {int(first)} if first.isdigit() else sets[first.upper()]
        assert fixed and not fixed & table, deck
    blocks = keyword_blocks((solved["decks"] / f"{m.name}_ccx_lagrange.inp").read_text())
    on, k_of = {}, {}
    for n, (k, o, d) in enumerate(blocks):
        if k == "ELEMENT" and o["TYPE"] == "SPRING1":
            on[o["ELSET"]] = [int(line.split(",")[1]) for line in d]
        if k == "SPRING":
            k_of[o["ELSET"]] = float(d[1].split(",")[0])
    springs = {n for nodes in on.values() for n in nodes}
    assert springs and springs <= table & corners
    assert sum(k_of[e] * len(nodes) for e, nodes in on.items()) == pytest.approx(float(np.sum(mesh.k_tangent)),
                                                                                  rel=1e-9)


# Nastran's mid-side grids: the edge (corner grids, 1-based) of each, in grid order after the corners (QRG CHEXA,
# CPENTA, CTETRA)
NASTRAN_EDGES = {
    "CHEXA": ((1, 2), (2, 3), (3, 4), (4, 1), (1, 5), (2, 6), (3, 7), (4, 8), (5, 6), (6, 7), (7, 8), (8, 5)),
    "CPENTA": ((1, 2), (2, 3), (3, 1), (1, 4), (2, 5), (3, 6), (4, 5), (5, 6), (6, 4)),
    "CTETRA": ((1, 2), (2, 3), (3, 1), (1, 4), (2, 4), (3, 4))}
CORNERS = {"CHEXA": 8, "CPENTA": 6, "CTETRA": 4}


@pytest.fixture(scope="module")
def tet_files(tmp_path_factory):
    return gmsh_mixed(tmp_path_factory.mktemp("tet_wedge"), order=2, n_theta=48, n_z=3, n_r=1, tet_layers=2)


@pytest.mark.parametrize("which", ["hex_wedge", "hex20r_wedge", "tet_wedge"])
def test_every_dialect_on_a_second_order_mixed_mesh(files, tet_files, tmp_path, which):
    """C3D20 + C3D15, C3D20R + C3D15 (Gmsh's file with its C3D20 renamed) and C3D10 + C3D15 (a wedge layer at the base
    under tetrahedra): the CalculiX mortar and
    face-to-face decks, the Abaqus decks and the Simcenter surface-contact deck are written; the node-based ones
    (Nastran and MYSTRAN CGAP) are left out with one line that says why; with the radial stop the CalculiX and Abaqus
    ones are too (node-based there), the Simcenter deck adds its stop layer.
    pyNastran reads the surface deck back: the skirt's cells with their grid counts (20 / 15 / 10), every mid-side
    grid at the middle of its edge in Nastran's order (within 5 % of the edge), the table layer one CHEXA 20 under
    each quad8 face and one CPENTA 15 under each tri6 face; the Abaqus and CalculiX decks carry both types cell by
    cell."""
    from pyNastran.bdf.bdf import read_bdf

    from deckbridge.deck_elements import MIXED_QUADRATIC_DIALECTS, element_problem
    from deckbridge.importers.inp_file import read_inp
    from deckbridge.mesh import build_mesh
    from deckbridge.numbering.skirt import mesh_node_ids
    from deckbridge.render import render_all
    f = tet_files if which == "tet_wedge" else files
    if which == "hex20r_wedge":
        reduced = tmp_path / "reduced.inp"
        reduced.write_text(Path(files["inp"]).read_text().replace("type=C3D20,", "type=C3D20R,"))
        f = {**files, "inp": str(reduced)}
    m = _model(f)
    mesh = build_mesh(m)
    names = {"hex_wedge": ("C3D20", "C3D15"), "hex20r_wedge": ("C3D20R", "C3D15"),
             "tet_wedge": ("C3D15", "C3D10")}[which]
    assert tuple(n.upper() for n, _ in mesh.blocks) == names
    notes = []
    paths = render_all(m, tmp_path / "decks", mesh=mesh, on_unsupported=notes.append)
    assert {p.name for p in paths} >= {f"{m.name}_{d}" for d in ("ccx_lagrange.inp", "ccx_f2f.inp", "lagrange.inp",
                                                                  "surface.bdf")}
    assert sorted(n.dialect for n in notes) == ["mystran", "nastran"]
    for n in notes:
        assert "\n" not in str(n) and f"({' + '.join(names)})" in str(n) and "node-based" in str(n), str(n)
    stop = _model(f, "contact.stop.side=inner")
    stop_mesh = build_mesh(stop)
    assert MIXED_QUADRATIC_DIALECTS == ("calculix", "abaqus", "nastran_surface")
    for dialect in ("calculix", "abaqus"):
        why = element_problem(dialect, stop, stop_mesh)
        assert "radial stop" in why and "\n" not in why, why
    cells = {n.upper(): c for n, c in mesh.blocks}
    for deck in ("lagrange", "ccx_lagrange", "ccx_f2f"):
        raw = read_inp(tmp_path / "decks" / f"{m.name}_{deck}.inp")
        for t, c in cells.items():
            assert {tuple(x) for x in raw.elements[t][1]} == {tuple(x) for x in mesh_node_ids(mesh, c)}, (deck, t)
    bdf = read_bdf(str(tmp_path / "decks" / f"{m.name}_surface.bdf"), xref=False, debug=None)
    xyz = {g: np.array(n.xyz) for g, n in bdf.nodes.items()}
    count = {}
    for e in bdf.elements.values():
        if e.type not in NASTRAN_EDGES:
            continue
        count[e.type, len(e.node_ids)] = count.get((e.type, len(e.node_ids)), 0) + 1
        g = [xyz[n] for n in e.node_ids]
        k = CORNERS[e.type]
        for (a, b), mid in zip(NASTRAN_EDGES[e.type], g[k:]):
            assert np.linalg.norm(mid - (g[a - 1] + g[b - 1]) / 2) <= 0.05 * np.linalg.norm(g[a - 1] - g[b - 1]), e
    faces = {ft.name: c.shape[0] for ft, c in mesh.table_faces}
    card = {"C3D20": ("CHEXA", 20), "C3D20R": ("CHEXA", 20), "C3D15": ("CPENTA", 15), "C3D10": ("CTETRA", 10)}
    want = {card[t]: c.shape[0] for t, c in cells.items()}
    want[("CHEXA", 20)] = want.get(("CHEXA", 20), 0) + faces.get("quad8", 0)
    want[("CPENTA", 15)] = want.get(("CPENTA", 15), 0) + faces.get("tri6", 0)
    assert count == {k: v for k, v in want.items() if v}
    assert sum(len(b.eids) for b in bdf.bsurfs.values()) == 2 * sum(faces.values())    # source and target faces
    _stop_layer_on_the_inner_circle(stop, stop_mesh, tmp_path / "stop", count)


def _stop_layer_on_the_inner_circle(model, mesh, folder, without_stop: dict) -> None:
    """The Simcenter deck with the inner radial stop: one CHEXA 20 under each first-row wall face on the inner circle
    (quad8 faces of a C3D20 or of a C3D15 of the base layer), as many as the base's edges on that circle (its corner
    nodes there), every one of their grids inside the wall."""
    from pyNastran.bdf.bdf import read_bdf

    from deckbridge.deck_elements import element_problem
    from deckbridge.render import render_all
    assert element_problem("nastran_surface", model, mesh) is None
    render_all(model, folder, mesh=mesh, names=["nastran_surface"])
    bdf = read_bdf(str(folder / f"{model.name}_surface.bdf"), xref=False, debug=None)
    count = {}
    for e in bdf.elements.values():
        if e.type in NASTRAN_EDGES:
            count[e.type, len(e.node_ids)] = count.get((e.type, len(e.node_ids)), 0) + 1
    extra = {k: v - without_stop.get(k, 0) for k, v in count.items() if v != without_stop.get(k, 0)}
    r = np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 1])
    r_in = r[mesh.table.nodes].min()
    corners = np.unique(np.concatenate([c[:, :f.n_corners].ravel() for f, c in mesh.table_faces]))
    n_edges = int(np.sum(np.abs(r[corners] - r_in) <= 1e-6 * r_in))
    assert extra == {("CHEXA", 20): n_edges} and n_edges >= 48, (extra, n_edges)
    layer = sorted((e for e in bdf.elements.values() if e.type == "CHEXA"), key=lambda e: e.eid)[-n_edges:]  # last
    radii = [np.hypot(*np.array(bdf.nodes[g].xyz)[:2]) for e in layer for g in e.node_ids]
    assert len(layer) == n_edges and max(radii) <= r_in * (1 + 1e-9)


def test_face_to_face_slopes_on_quad8_and_tri6_faces_add_up_to_the_nodes_k(files, tmp_path):
    """With an explicit contact.penalty.k_normal (the same k on every node, unequal areas) the face-to-face deck's
    LINEAR slopes differ from face to face (deck_elements.quadratic_face_slopes, on each cell's own face type): read
    back from the deck, Sum over the slave faces of K_f x the face's area (its hat shares, face_weights.face_shares)
    is the nodes' Sum k (measured 2.3e-9: faces of slopes within 1e-6 share one pair), and every pair has its own
    master surface (quadratic_master.pair_masters)."""
    from deckbridge.importers.inp_mesh import keyword_blocks
    from deckbridge.mesh import build_mesh
    from deckbridge.numbering.skirt import elem_ids
    from deckbridge.render import render_all
    from reference_solver.elements import element_type
    from reference_solver.face_weights import face_shares
    k = 1.0e8
    m = _model(files, f"contact.penalty.k_normal={k}")
    mesh = build_mesh(m)
    render_all(m, tmp_path, mesh=mesh, names=["calculix"])
    blocks = keyword_blocks((tmp_path / f"{m.name}_ccx_f2f.inp").read_text())
    faces = {o["NAME"]: d for key, o, d in blocks if key == "SURFACE"}
    slope = {}
    for n, (key, o, d) in enumerate(blocks):
        if key == "SURFACE INTERACTION":
            slope[o["NAME"]] = float(blocks[n + 1][2][0].split(",")[0])
    pairs = [(o["INTERACTION"], d[0].split(",")) for key, o, d in blocks if key == "CONTACT PAIR"]
    assert len(pairs) > 1 and len({mst.strip() for _, (_, mst) in pairs}) == len(pairs)
    row = {int(e): i for i, e in enumerate(elem_ids(mesh, np.arange(mesh.hexes.shape[0])))}
    types = [element_type(n) for n, c in mesh.blocks for _ in range(c.shape[0])]
    total, seen = 0.0, 0
    for inter, (slave, _) in pairs:
        for line in faces[slave.strip()]:
            e, s = line.split(",")
            cell = row[int(e)]
            local = list(types[cell].faces[int(s.strip()[1:]) - 1])
            conn = mesh.hexes[cell, local]
            ftype = types[cell].face_types[int(s.strip()[1:]) - 1]
            total += slope[inter] * face_shares(ftype, mesh.nodes[conn][None]).sum()
            seen += 1
    assert seen == sum(c.shape[0] for _, c in mesh.table_faces)
    assert total == pytest.approx(k * mesh.table.nodes.size, rel=2e-6)   # faces within 1e-6 share a slope
