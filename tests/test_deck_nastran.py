"""Nastran penalty deck: read back with pyNastran (cross-referenced) and compared with values
recomputed here from the geometry of a uniform cylinder, not taken from the mesh module."""

from __future__ import annotations

import math

import numpy as np
import pytest
from pyNastran.bdf.bdf import BDF
from pyNastran.bdf.bdf_interface.utils import to_fields

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.render import render_all
from deckbridge.render.nastran import write
from deckbridge.numbering.nastran import numbering

N_T, N_Z, N_R, NINC = 24, 6, 1, 7
OVERRIDES = [f"mesh.n_theta={N_T}", f"mesh.n_z={N_Z}", f"mesh.n_r={N_R}", f"steps.increments={NINC}",
             "steps.lambda_max=0.8", "loads.azimuth=30", "contact.friction=0.15",
             "contact.penalty.open_ratio=1.0e-5", "contact.penalty.k_tangent=3.0e7"]


def _read(path) -> BDF:
    bdf = BDF(debug=None)
    bdf.read_bdf(str(path), xref=True)
    return bdf


@pytest.fixture(scope="module")
def deck(tmp_path_factory):
    model = load(None, OVERRIDES)
    mesh = build_mesh(model)
    path = write(model, mesh, tmp_path_factory.mktemp("nastran"))[0]
    return model, mesh, path, _read(path)


def _raw_cards(path, name):
    """Field lists of every ``name`` card as written (blank fields stay '')."""
    lines = path.read_text().splitlines()
    out = []
    for i, line in enumerate(lines):
        if line.startswith(name + "*") or line.startswith(name + " "):
            block = [line]
            j = i + 1
            while j < len(lines) and lines[j][:1] in ("*", " ", "+") and lines[j].strip():
                block.append(lines[j])
                j += 1
            out.append([f.strip() for f in to_fields(block, name)])
    return out


def _cylinder_penalties(model):
    """k_c = alpha * A_face * A_node / V for table and (inner) stop nodes of a faceted cylinder.

    Table: inner/outer chords a, b of the base face, a trapezoid of width w = t cos(pi / n)
    (the distance between its parallel chords), consistent nodal shares w (2a + b) / 6 and
    w (a + 2b) / 6 (two faces each), element volume V = w (a + b) h / 2, so A_face / V = 1 / h.
    Stop: inner wall face a x h, base-node share a h / 2.
    """
    g = model.geometry
    kb = model.material.E / (3 * (1 - 2 * model.material.nu))
    h = g.height / N_Z
    r_in, r_out = g.radius - g.thickness / 2, g.radius + g.thickness / 2
    s = 2 * math.sin(math.pi / N_T)
    a, b, t = r_in * s, r_out * s, g.thickness * math.cos(math.pi / N_T)
    vol = t * (a + b) / 2 * h
    alpha = model.contact.penalty.alpha
    a_in, a_out = t * (2 * a + b) / 6, t * (a + 2 * b) / 6
    k_in, k_out = alpha * kb * a_in / h, alpha * kb * a_out / h
    k_stop = alpha * kb * (a * h) * (a * h / 2) / vol
    return {"table_inner": (k_in, r_in), "table_outer": (k_out, r_out), "stop": (k_stop, r_in)}


def test_gap_count_penalties_axes(deck):
    model, mesh, path, bdf = deck
    gaps = [e for e in bdf.elements.values() if e.type == "CGAP"]
    n_table, n_stop = (N_R + 1) * N_T, N_T          # every base node, plus the inner-face base ring
    assert len(gaps) == n_table + n_stop
    ref = _cylinder_penalties(model)
    spc_nodes = set(bdf.spcs[1][0].node_ids)
    assert bdf.spcs[1][0].components == "123456"
    seen = {"table_inner": 0, "table_outer": 0, "stop": 0}
    for e in gaps:
        pa, pb = e.ga_ref.get_position(), e.gb_ref.get_position()
        axis = (pb - pa) / np.linalg.norm(pb - pa)
        r = math.hypot(pa[0], pa[1])
        assert abs(pa[2]) < 1e-12 and e.Gb() in spc_nodes and e.Ga() not in spc_nodes
        if abs(axis[2]) > 0.5:
            np.testing.assert_allclose(axis, [0, 0, -1], atol=1e-12)
            key = "table_inner" if r < model.geometry.radius else "table_outer"
        else:   # inner stop: master normal points outward into the wall, gap axis inward
            np.testing.assert_allclose(axis, [-pa[0] / r, -pa[1] / r, 0.0], atol=1e-12)
            key = "stop"
        k_expected, r_expected = ref[key]
        assert r == pytest.approx(r_expected, rel=1e-12)
        p = e.pid_ref
        assert p.ka == pytest.approx(k_expected, rel=1e-10)
        assert p.kb == pytest.approx(1.0e-5 * k_expected, rel=1e-10)
        assert (p.u0, p.f0, p.tmax) == (0.0, 0.0, 0.0)
        # the circumferential CELAS2 carry T: KT = 0 (one tangential mechanism), MU from the model
        assert p.kt == 0.0 and p.mu1 == p.mu2 == 0.15
        seen[key] += 1
    assert seen == {"table_inner": N_T, "table_outer": N_T, "stop": N_T}


def test_pgap_fields_written_explicitly(deck):
    path = deck[2]
    cards = _raw_cards(path, "PGAP")
    assert len(cards) == 3 * N_T
    for f in cards:  # PGAP PID U0 F0 KA KB KT MU1 MU2 TMAX MAR TRMIN: none blank
        assert len(f) >= 12 and all(x != "" for x in f[1:12]), f
        assert float(f[9]) == 0.0          # TMAX = 0: no adaptive penalty


def test_subcases_loads_and_nlparm(deck):
    model, mesh, path, bdf = deck
    cc = bdf.case_control_deck
    assert bdf.sol == 106
    lam = model.steps.lambda_max
    v = model.load_vectors()
    expect = {1: (np.array(v["N_force"]), np.zeros(3), 1),
              2: (np.array(v["N_force"]) + lam * np.array(v["T_force"]), lam * np.array(v["M_moment"]), NINC)}
    for sc, (force, moment, ninc) in expect.items():
        load_id = cc.subcases[sc].get_parameter("LOAD")[0]
        combo = bdf.load_combinations[load_id][0]
        f_tot, m_tot = np.zeros(3), np.zeros(3)
        for scale, sid in zip(combo.scale_factors, combo.load_ids):
            for card in bdf.loads[sid]:
                vec = combo.scale * scale * card.mag * np.asarray(card.xyz)
                if card.type == "FORCE":
                    f_tot += vec
                else:
                    m_tot += vec
        np.testing.assert_allclose(f_tot, force, atol=1e-6 * model.loads.N)
        np.testing.assert_allclose(m_tot, moment, atol=1e-6 * model.loads.M)
        nl = bdf.nlparms[cc.subcases[sc].get_parameter("NLPARM")[0]]
        assert nl.ninc == ninc and nl.int_out == "YES"
    raw = _raw_cards(path, "NLPARM")
    assert len(raw) == 2
    for f in raw:   # ID NINC DT KMETHOD KSTEP MAXITER CONV INTOUT EPSU EPSP EPSW: all written
        assert all(x != "" for x in f[1:12]), f


# --- one round trip per card type -------------------------------------------------------------
def _check_grid(model, mesh, bdf):
    for i, xyz in enumerate(mesh.nodes):
        node = bdf.nodes[i + 1]
        np.testing.assert_allclose(node.get_position(), xyz, atol=1e-13)
        assert node.cd == (1 if xyz[2] == 0.0 else 0)
    assert bdf.coords[1].type == "CORD2C"
    np.testing.assert_allclose(bdf.coords[1].k, [0, 0, 1])   # cylinder axis = basic z
    np.testing.assert_allclose(bdf.coords[1].i, [1, 0, 0])   # theta = 0 along +x


def _check_chexa(model, mesh, bdf):
    hexas = {e.eid: e for e in bdf.elements.values() if e.type == "CHEXA"}
    assert len(hexas) == mesh.hexes.shape[0]
    g = model.geometry   # faceted annulus: N_T trapezoids, chords 2 r sin(pi/n), width t cos(pi/n)
    vol = N_T * g.thickness * math.cos(math.pi / N_T) * 2 * g.radius * math.sin(math.pi / N_T) * g.height
    total = 0.0
    for e, h in enumerate(mesh.hexes):
        assert hexas[e + 1].node_ids == [int(n) + 1 for n in h]
        total += hexas[e + 1].Volume()
    assert total == pytest.approx(vol, rel=1e-9)
    mat = bdf.materials[1]
    assert (mat.e, mat.nu) == (model.material.E, model.material.nu)


def _check_cgap(model, mesh, bdf):
    """X1-X3 are components in GA's displacement system CD: transformed to basic with pyNastran's
    own cylindrical rotation at GA's azimuth, every vector is unit, perpendicular to the gap axis,
    and radial for the vertical (table) gaps."""
    n = 0
    for e in (e for e in bdf.elements.values() if e.type == "CGAP"):
        x_basic = _cd_vector_to_basic(e.ga_ref, np.asarray(e.x, float))
        pa = e.ga_ref.get_position()
        axis = e.gb_ref.get_position() - pa
        assert abs(np.dot(x_basic, axis)) < 1e-12 * np.linalg.norm(axis)
        assert np.linalg.norm(x_basic) == pytest.approx(1.0, rel=1e-12)
        if abs(axis[2]) > 0.5 * np.linalg.norm(axis):      # table gap: radial
            radial = np.array([pa[0], pa[1], 0.0]) / math.hypot(pa[0], pa[1])
            np.testing.assert_allclose(x_basic, radial, atol=1e-12)
            n += 1
        assert e.pid == e.eid and e.cid is None
    assert n == mesh.table.nodes.size


def _cd_vector_to_basic(grid, v):
    """Components ``v`` in the grid's displacement system -> basic (pyNastran's coords and rotation)."""
    from pyNastran.femutils.coord_transforms import cylindrical_rotation_matrix

    cd = grid.cd_ref
    if cd.type == "CORD2R" or cd.cid == 0:
        return v @ cd.beta()
    assert cd.type == "CORD2C"
    theta = np.radians(cd.xyz_to_coord(grid.get_position())[1])
    rot = cylindrical_rotation_matrix(np.array([theta]), dtype="float64")[0]
    return (rot @ v) @ cd.beta()     # as pyNastran transforms CD displacements (dot_n33_n3)


def _check_pgap(model, mesh, bdf):
    kas = sorted(p.ka for p in bdf.properties.values() if p.type == "PGAP")
    np.testing.assert_allclose(kas, np.sort(np.concatenate([mesh.table.k, mesh.stop.k])), rtol=1e-13)


def _check_rbe3(model, mesh, bdf):
    (rbe,) = bdf.rigid_elements.values()
    assert rbe.type == "RBE3" and rbe.refc == "123456"
    ref = bdf.nodes[rbe.refgrid].get_position()
    np.testing.assert_allclose(ref, [0, 0, model.geometry.height])
    got = {}
    for w, comp, ids in zip(rbe.weights, rbe.comps, rbe.Gijs):
        assert comp == "123"
        got.update({nid: w for nid in ids})
    # weights = tributary area on the top face, recomputed for the faceted annulus
    g, s = model.geometry, 2 * math.sin(math.pi / N_T)
    a, b = (g.radius - g.thickness / 2) * s, (g.radius + g.thickness / 2) * s
    assert sorted(got) == sorted(int(n) + 1 for n in mesh.top_nodes)
    for nid, w in got.items():
        r = math.hypot(*bdf.nodes[nid].get_position()[:2])
        share = g.thickness * math.cos(math.pi / N_T) * ((2 * a + b) if r < g.radius else (a + 2 * b)) / 6
        assert w == pytest.approx(share, rel=1e-9)


def _check_celas2(model, mesh, bdf):
    springs = [e for e in bdf.elements.values() if e.type == "CELAS2"]
    assert len(springs) == mesh.table.nodes.size
    for e in springs:
        assert e.k == 3.0e7 and e.c1 == 2 and e.nodes[1] is None and e.c2 == 0   # theta, grounded
        assert e.nodes_ref[0].cd == 1 and e.nodes_ref[0].get_position()[2] == 0.0


def _check_force(model, mesh, bdf):
    a = math.radians(model.loads.azimuth)
    (fn,), (ft,) = bdf.loads[11], bdf.loads[12]
    np.testing.assert_allclose(fn.mag * fn.xyz, [0, 0, -model.loads.N])
    np.testing.assert_allclose(ft.mag * ft.xyz, [-model.loads.T * math.cos(a), -model.loads.T * math.sin(a), 0],
                               atol=1e-9)
    assert fn.node == ft.node == bdf.rigid_elements[next(iter(bdf.rigid_elements))].refgrid


def _check_moment(model, mesh, bdf):
    (mm,) = bdf.loads[13]
    a = math.radians(model.loads.azimuth)
    vec = mm.mag * np.asarray(mm.xyz)
    # the moment lifts the azimuth side: its vector is the tension-side direction turned by -90 deg
    np.testing.assert_allclose(np.cross([math.cos(a), math.sin(a), 0], vec), [0, 0, -model.loads.M], atol=1e-6)


def _check_load(model, mesh, bdf):
    lam = model.steps.lambda_max
    c1, c2 = bdf.load_combinations[101][0], bdf.load_combinations[102][0]
    assert (c1.scale, c1.scale_factors, c1.load_ids) == (1.0, [1.0], [11])
    assert (c2.scale, c2.scale_factors, c2.load_ids) == (1.0, [1.0, lam, lam], [11, 12, 13])


def _check_nlparm(model, mesh, bdf):
    n1, n2 = bdf.nlparms[1], bdf.nlparms[2]
    assert (n1.ninc, n2.ninc) == (1, NINC)
    for n in (n1, n2):
        assert (n.kmethod, n.kstep, n.max_iter, n.conv, n.int_out) == ("ITER", 1, 25, "UPW", "YES")
        assert (n.eps_u, n.eps_p, n.eps_w) == (1e-3, 1e-3, 1e-7)


CHECKS = {"GRID": _check_grid, "CHEXA": _check_chexa, "CGAP": _check_cgap, "PGAP": _check_pgap,
          "RBE3": _check_rbe3, "CELAS2": _check_celas2, "FORCE": _check_force, "MOMENT": _check_moment,
          "LOAD": _check_load, "NLPARM": _check_nlparm}


@pytest.mark.parametrize("card", sorted(CHECKS))
def test_card_round_trip(deck, card):
    model, mesh, path, bdf = deck
    assert bdf.card_count[card] >= 1
    CHECKS[card](model, mesh, bdf)


def test_rbe2_for_kinematic(tmp_path):
    model = load(None, OVERRIDES + ["load_introduction=kinematic"])
    mesh = build_mesh(model)
    bdf = _read(write(model, mesh, tmp_path)[0])
    (rbe,) = bdf.rigid_elements.values()
    assert rbe.type == "RBE2" and rbe.cm == "123456"
    assert sorted(rbe.independent_nodes) == [numbering(mesh).ref_node]
    assert sorted(rbe.dependent_nodes) == sorted(int(n) + 1 for n in mesh.top_nodes)


def test_title_cannot_inject_cards(tmp_path):
    evil = load(None, OVERRIDES).with_overrides({"title": "JAR\n$ x\nGRID,999\nBEGIN BULK\n*"})
    clean = load(None, OVERRIDES)
    counts = []
    for model, sub in ((evil, "evil"), (clean, "clean")):
        out = tmp_path / sub
        paths = render_all(model, out, ["nastran"])
        assert [p.name for p in paths] == ["JAR_penalty.bdf"]
        bdf = _read(paths[0])
        assert 999 not in bdf.nodes
        counts.append(dict(bdf.card_count))
    assert counts[0] == counts[1]
    text = (tmp_path / "evil" / "JAR_penalty.bdf").read_text()
    lines = text.splitlines()
    assert not any(line.startswith("GRID,") for line in lines)
    assert sum(line.startswith("BEGIN BULK") for line in lines) == 1


# --- issue 10: one analysis, said in the deck ------------------------------------------------------
def _mystran_deck(overrides, folder):
    from deckbridge.render.mystran import write as write_mystran

    model = load(None, overrides)
    return write_mystran(model, build_mesh(model), folder)[0]


def test_rewritten_deck_reads_back_with_the_same_fields(deck, tmp_path):
    """pyNastran round trip, every card type: read the deck, write it, read again: same fields."""
    path, bdf = deck[2], deck[3]
    bdf2 = BDF(debug=None)
    out = tmp_path / "again.bdf"
    first = BDF(debug=None)
    first.read_bdf(str(path), xref=False)
    first.write_bdf(str(out), size=16)
    bdf2.read_bdf(str(out), xref=False)
    types = set(first.card_count) - {"ENDDATA"}
    assert {"GRID", "CHEXA", "CGAP", "PGAP", "PSOLID", "MAT1", "CORD2C", "SPC1", "CELAS2", "RBE3", "FORCE",
            "MOMENT", "LOAD", "NLPARM", "PARAM"} <= types
    for name in ("nodes", "elements", "properties", "materials", "coords", "rigid_elements", "nlparms", "params"):
        a, b = getattr(first, name), getattr(bdf2, name)
        assert sorted(a) == sorted(b), name
        for key in a:
            assert a[key].raw_fields() == b[key].raw_fields(), (name, key)
    for name in ("loads", "load_combinations", "spcs"):
        a, b = getattr(first, name), getattr(bdf2, name)
        assert sorted(a) == sorted(b)
        for key in a:
            assert [c.raw_fields() for c in a[key]] == [c.raw_fields() for c in b[key]], (name, key)


def test_psolid_in_per_solver(deck, tmp_path):
    """SOL 106: IN blank (MSC's CHEXA8 default, bubble functions = C3D8I); MYSTRAN: IN = 2 (TWO)."""
    (penalty,) = _raw_cards(deck[2], "PSOLID")
    assert penalty[1:3] == ["1", "1"] and all(f == "" for f in penalty[3:])
    (linear,) = _raw_cards(_mystran_deck(OVERRIDES, tmp_path), "PSOLID")
    assert linear[4] in ("2", "TWO")


def test_mat1_e_and_nu_only(deck):
    (mat,) = _raw_cards(deck[2], "MAT1")
    model = deck[0]
    assert float(mat[2]) == model.material.E and mat[3] == "" and float(mat[4]) == model.material.nu


def test_every_load_card_is_used(deck, tmp_path):
    """No dead cards: every LOAD is a subcase's LOAD, every FORCE/MOMENT set is in a used LOAD."""
    for path in (deck[2], _mystran_deck(OVERRIDES, tmp_path)):
        bdf = _read(path)
        used = {sc.get_parameter("LOAD")[0] for i, sc in bdf.case_control_deck.subcases.items() if i > 0}
        assert set(bdf.load_combinations) == used
        referenced = {sid for lid in used for sid in bdf.load_combinations[lid][0].load_ids}
        assert set(bdf.loads) == referenced


def test_stress_output_on_the_bottom_row(deck, tmp_path):
    """STRESS(CORNER) on a SET holding exactly the CHEXAs whose base face lies on z = 0."""
    model, mesh = deck[0], deck[1]
    for path in (deck[2], _mystran_deck(OVERRIDES, tmp_path)):
        bdf = _read(path)
        sc = bdf.case_control_deck.subcases[0]
        value, options = sc.get_parameter("STRESS")
        if "penalty" in path.name:
            options = [o.strip() for o in options]
            assert "CORNER" in options and "PLOT" in options and bdf.params["POST"].values == [-1]
        ids = sc.get_parameter(f"SET {value}")[0] if f"SET {value}" in sc.params else None
        assert ids is not None
        bottom = [e.eid for e in bdf.elements.values() if e.type == "CHEXA"
                  and max(abs(bdf.nodes[n].get_position()[2]) for n in e.node_ids[:4]) < 1e-12]
        assert sorted(ids) == sorted(bottom) and len(bottom) == N_T * N_R


@pytest.mark.parametrize("nlgeom,lgdisp", [(False, -1), (True, 1)])
def test_lgdisp_from_analysis_nlgeom(tmp_path, nlgeom, lgdisp):
    model = load(None, OVERRIDES + [f"analysis.nlgeom={str(nlgeom).lower()}"])
    bdf = _read(write(model, build_mesh(model), tmp_path)[0])
    assert bdf.params["LGDISP"].values == [lgdisp]


def test_no_round_off_residues(tmp_path):
    """Azimuth 90 deg: cos = 6e-17 in floating point; no such residue reaches a card."""
    over = OVERRIDES + ["loads.azimuth=90"]
    model = load(None, over)
    for path in (write(model, build_mesh(model), tmp_path)[0], _mystran_deck(over, tmp_path)):
        bdf = _read(path)
        vectors = [np.asarray(c.xyz, float) for cards in bdf.loads.values() for c in cards]
        vectors += [np.asarray(n.xyz, float) for n in bdf.nodes.values()]
        vectors += [np.asarray(e.x, float) for e in bdf.elements.values() if e.type == "CGAP"]
        for v in vectors:
            tiny = (v != 0) & (np.abs(v) < 1e-12 * np.abs(v).max())
            assert not tiny.any(), v
        (fy,) = bdf.loads[12]
        assert list(fy.xyz) == [0.0, -1.0, 0.0]


def test_mm_deck_is_the_si_deck_scaled(tmp_path):
    """units: mm -> coordinates x1e3, E in MPa, KA/KB/CELAS2 in N/mm, moments in N mm, forces in N,
    U0 in mm; the header says so in a parseable line."""
    decks = {}
    for u in ("SI", "mm"):
        model = load(None, OVERRIDES + [f"units={u}", "contact.stop.radius=1.489"])
        (tmp_path / u).mkdir()
        path = write(model, build_mesh(model), tmp_path / u)[0]
        assert f"$ deckbridge-units: {u}\n" in path.read_text()
        decks[u] = _read(path)
    si, mm = decks["SI"], decks["mm"]
    for nid, node in si.nodes.items():
        np.testing.assert_allclose(mm.nodes[nid].xyz, 1e3 * np.asarray(node.xyz), rtol=1e-14, atol=1e-12)
    assert mm.materials[1].e == pytest.approx(si.materials[1].e * 1e-6, rel=1e-15)
    assert mm.materials[1].nu == si.materials[1].nu
    for pid, p in si.properties.items():
        if p.type == "PGAP":
            q = mm.properties[pid]
            for f, factor in (("ka", 1e-3), ("kb", 1e-3), ("kt", 1e-3), ("u0", 1e3), ("mu1", 1.0)):
                assert getattr(q, f) == pytest.approx(getattr(p, f) * factor, rel=1e-12, abs=1e-300)
    for eid, e in si.elements.items():
        if e.type == "CELAS2":
            assert mm.elements[eid].k == pytest.approx(e.k * 1e-3, rel=1e-14)
    assert mm.loads[11][0].mag == si.loads[11][0].mag
    assert mm.loads[13][0].mag == pytest.approx(si.loads[13][0].mag * 1e3, rel=1e-15)
    assert any(p.u0 > 0 for p in si.properties.values() if p.type == "PGAP")


def test_deck_modes_follow_the_umask(tmp_path):
    import os
    old = os.umask(0o027)
    try:
        paths = render_all(load(None, OVERRIDES), tmp_path, ["nastran", "mystran"])
    finally:
        os.umask(old)
    assert [oct(p.stat().st_mode & 0o777) for p in paths] == [oct(0o640)] * 2


def test_model_vtu_beside_the_decks(tmp_path):
    """render_all writes <name>_model.vtu once: the deck ids and the sets, read back by meshio and
    compared with the penalty deck read by pyNastran."""
    import meshio

    model = load(None, OVERRIDES + ["contact.friction=0"])     # every dialect renders it
    paths = render_all(model, tmp_path)
    assert sum(p.name.endswith("_model.vtu") for p in paths) == 1
    vtu = meshio.read(tmp_path / "JAR_model.vtu")
    bdf = _read(tmp_path / "JAR_penalty.bdf")
    ids = vtu.point_data["node_id"]
    for i, nid in enumerate(ids):
        np.testing.assert_allclose(vtu.points[i], bdf.nodes[int(nid)].get_position(), atol=1e-12)
    gaps = [e for e in bdf.elements.values() if e.type == "CGAP"]
    vertical = {e.eid: abs((e.gb_ref.get_position() - e.ga_ref.get_position())[2]) > 0 for e in gaps}
    table = {e.Ga() for e in gaps if vertical[e.eid]}
    stop = {e.Ga() for e in gaps if not vertical[e.eid]}
    assert stop and table
    assert set(ids[vtu.point_data["table_slave"] == 1]) == table
    assert set(ids[vtu.point_data["stop_slave"] == 1]) == stop
    rbe = next(iter(bdf.rigid_elements.values()))
    assert set(ids[vtu.point_data["top_ring"] == 1]) == {n for g in rbe.Gijs for n in g}
    (cells,) = vtu.cells
    eids = vtu.cell_data["element_id"][0]
    for k, eid in enumerate(eids):
        assert [int(ids[n]) for n in cells.data[k]] == bdf.elements[int(eid)].node_ids
    sc = bdf.case_control_deck.subcases[0]
    stress_set = sc.get_parameter(f"SET {sc.get_parameter('STRESS')[0]}")[0]
    assert sorted(eids[vtu.cell_data["bottom_row"][0] == 1]) == sorted(stress_set)
