"""The Nastran-family decks describe one analysis and say so (issue 10): field semantics that
pyNastran accepts silently, checked on the decks read back by pyNastran (cross-referenced), units,
file modes and the model VTU beside the decks."""

from __future__ import annotations

import numpy as np
import pytest
from pyNastran.bdf.bdf import BDF

from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.render import render_all
from deckbridge.dialects.nastran.render import write
from test_deck_nastran import N_R, N_T, OVERRIDES, _raw_cards, _read, deck  # noqa: F401 (fixture)

def _mystran_deck(overrides, folder):
    from deckbridge.dialects.mystran.render import write as write_mystran

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


def _with_tangential(value: str):
    """The model with issue 14's ``contact.tangential`` (absent from this branch's model) set."""
    model = load(None, OVERRIDES)
    object.__setattr__(model.contact, "tangential", value)
    return model


def test_one_tangential_mechanism(tmp_path):
    """Springs (default): CELAS2 on theta and PGAP KT = 0. Friction: PGAP KT = the node's k_t with
    MU1 = MU2 = mu and no CELAS2; the MYSTRAN deck refuses it in one line."""
    from deckbridge.errors import DeckbridgeError
    from deckbridge.dialects.mystran.render import write as write_mystran

    model = _with_tangential("friction")
    mesh = build_mesh(model)
    bdf = _read(write(model, mesh, tmp_path)[0])
    assert "CELAS2" not in bdf.card_count
    gaps = [e for e in bdf.elements.values() if e.type == "CGAP"]
    vertical = [abs(e.gb_ref.get_position()[2] - e.ga_ref.get_position()[2]) > 0 for e in gaps]
    table = [e.pid_ref for e, v in zip(gaps, vertical) if v]
    stop = [e.pid_ref for e, v in zip(gaps, vertical) if not v]
    assert table and stop
    assert all(p.kt == pytest.approx(3.0e7, rel=1e-15) and p.mu1 == p.mu2 == 0.15 for p in table)
    assert all(p.kt == p.mu1 == p.mu2 == 0.0 for p in stop)      # the radial stop is frictionless
    assert "PGAP KT (stick)" in (tmp_path / "JAR_penalty.bdf").read_text()
    with pytest.raises(DeckbridgeError, match="contact.tangential = friction") as exc:
        write_mystran(model, mesh, tmp_path)
    assert "\n" not in str(exc.value)
    springs = _with_tangential("springs")
    bdf = _read(write(springs, build_mesh(springs), tmp_path)[0])
    assert bdf.card_count["CELAS2"] == mesh.table.nodes.size
    assert all(p.kt == 0.0 for p in bdf.properties.values() if p.type == "PGAP")


def test_header_states_ka_over_element_stiffness(deck):
    """Table: KA/(E A/h) = alpha K / E = alpha / (3 (1 - 2 nu)) (closed form, uniform cylinder)."""
    import re

    model, path = deck[0], deck[2]
    text = path.read_text()
    m = re.search(r"^\$   table \((\d+) nodes\): KA = .* N/m; KA/\(E A/L\) = ([0-9.e+-]+)$", text, re.M)
    assert m and int(m.group(1)) == (N_R + 1) * N_T
    expected = model.contact.penalty.alpha / (3 * (1 - 2 * model.material.nu))
    assert float(m.group(2)) == pytest.approx(expected, rel=1e-3)
    assert "$ deckbridge-units: SI" in text and "PARAM,LGDISP,-1" in text
