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
from deckbridge.dialects.nastran.render import write
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
        # the circumferential CELAS2 carry T: KT = 0 (one tangential mechanism), MU from the model at the
        # table, 0 at the stop (frictionless, issue 21 item 6)
        assert p.kt == 0.0 and p.mu1 == p.mu2 == (0.0 if key == "stop" else 0.15)
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

