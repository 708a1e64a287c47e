"""The Simcenter surface-contact deck: read back by pyNastran with cross-referencing, card by card against the
layout of the real Femap-written Simcenter model (../shared/data/nx_surface_contact), geometry against closed
forms. MYSTRAN is not a check here: it accepts these cards and ignores them (REFERENCE.md section 9).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest
from pyNastran.bdf.bdf import read_bdf

from deckbridge.dialects import DIALECTS
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.numbering.nastran import numbering
from deckbridge.dialects.nastran_surface.reader import source_faces

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "nx_surface_contact"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"shared Simcenter surface-contact model absent ({DATA})")
CONTACT_CARDS = {"BSURFS", "BCRPARA", "BCTSET", "BCTPARM", "BCTADD", "BSURF", "BCPROP", "BCTPARA"}
SMALL = ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=2"]


def _deck(tmp_path, overrides=()):
    model = load(None, list(overrides))
    (path,) = DIALECTS["nastran_surface"].write(model, build_mesh(model), tmp_path)
    return model, path


def _face_of(bdf, eid, three):
    """The corner grids of the face of element ``eid`` that holds the three grids (pyNastran's face table)."""
    faces = [f for f in bdf.elements[eid].faces.values() if set(three) <= set(f)]
    assert len(faces) == 1, (eid, three)
    return faces[0]


def _area(bdf, face):
    x = np.array([bdf.nodes[g].get_position() for g in face])
    return 0.5 * np.linalg.norm(np.cross(x[2] - x[0], x[3] - x[1])), x


def _case_lines(path: Path) -> list[str]:
    text = path.read_text()
    return [ln.strip() for ln in text[:text.index("BEGIN BULK")].splitlines() if ln.strip() and not ln.startswith("$")]


def test_read_back_with_cross_referencing(tmp_path):
    model, path = _deck(tmp_path, SMALL)
    bdf = read_bdf(str(path), xref=True, debug=None)          # raises on a dangling reference
    mesh = build_mesh(model)
    nt, nr = 24, 2
    assert bdf.card_count["BSURFS"] == 4 and bdf.card_count["BCRPARA"] == 4 and bdf.card_count["BCTSET"] == 1
    ct = bdf.bctsets[1]
    assert (ct.sids, ct.tids) == ([1, 3], [2, 4]) and ct.frictions == [0.0, 0.0]
    assert len(bdf.bsurfs[1].eids) == nt * nr and len(bdf.bsurfs[3].eids) == nt
    # every target-layer grid is clamped, and no skirt grid is
    clamped = {n for spc in bdf.spcs[1] for n in spc.node_ids}
    ref = numbering(mesh).ref_node
    assert ref in bdf.nodes and clamped == {n for n in bdf.nodes if n > ref}
    assert len(clamped) == 2 * (nt * (nr + 1)) + 2 * (2 * nt)       # table layer 2 x base grids, stop layer 2 x wall grids
    layer = [e for e in bdf.elements.values() if e.type == "CHEXA" and e.pid == 2]
    assert len(layer) == nt * nr + nt and min(e.Volume() for e in layer) > 0
    assert "BCSET = 1" in _case_lines(path) and "BCRESULTS(TRACTION,FORCE,SEPDIS) = ALL" in _case_lines(path)


def test_table_faces_cover_the_base_annulus_and_meet_their_targets(tmp_path):
    model, path = _deck(tmp_path, SMALL)
    bdf = read_bdf(str(path), xref=True, debug=None)
    g, nt = model.geometry, 24
    ro, ri = g.radius + g.thickness / 2, g.radius - g.thickness / 2
    polygon = 0.5 * nt * math.sin(2 * math.pi / nt) * (ro ** 2 - ri ** 2)        # the faceted base annulus
    src, tgt = bdf.bsurfs[1], bdf.bsurfs[2]
    total, tops = 0.0, {}
    for e, *three in zip(tgt.eids, tgt.g1s, tgt.g2s, tgt.g3s):
        a, x = _area(bdf, _face_of(bdf, e, three))
        tops[tuple(sorted(map(tuple, np.round(x, 12))))] = a
    for e, *three in zip(src.eids, src.g1s, src.g2s, src.g3s):
        a, x = _area(bdf, _face_of(bdf, e, three))
        assert np.allclose(x[:, 2], 0.0)                                       # base faces at z = 0
        key = tuple(sorted(map(tuple, np.round(x, 12))))
        assert tops[key] == pytest.approx(a, rel=1e-12)                        # clearance 0: the table top meets it
        total += a
    assert total == pytest.approx(polygon, rel=1e-12)
    # the stop target faces sit on the stop radius (clearance 0 here: the skirt's inner wall)
    for e, *three in zip(bdf.bsurfs[4].eids, bdf.bsurfs[4].g1s, bdf.bsurfs[4].g2s, bdf.bsurfs[4].g3s):
        _, x = _area(bdf, _face_of(bdf, e, three))
        assert np.hypot(x[:, 0], x[:, 1]) == pytest.approx(np.full(4, ri), rel=1e-12)


def test_reader_places_the_decks_own_faces(tmp_path):
    """The OP2 reader's geometry path on this deck: source grids = table slaves + stop wall face grids,
    shares summing to the faces' area, surfaces told apart by their normals."""
    model, path = _deck(tmp_path, SMALL)
    mesh = build_mesh(model)
    sf = source_faces(path)
    table_ids = set((mesh.table.nodes + 1).tolist())
    assert table_ids <= set(sf.xyz)
    assert {n for r, n in sf.share if r == 1} == table_ids
    assert sum(sf.share[1, n] for n in table_ids) == pytest.approx(float(mesh.table.area.sum()), rel=1e-12)
    assert all(abs(sf.normal[1, n][2]) > 0.99 for n in table_ids)
    stop = {n for r, n in sf.share if r == 3}
    assert set((mesh.stop.nodes + 1).tolist()) < stop and all(abs(sf.normal[3, n][2]) < 1e-9 for n in stop)


@needs_data
def test_layout_follows_the_real_simcenter_deck(tmp_path):
    _, path = _deck(tmp_path, SMALL)
    ours = read_bdf(str(path), xref=True, debug=None)
    real = read_bdf(str(DATA / "contact_model.bdf"), xref=True, debug=None)
    kinds = lambda b: {c for c in b.card_count if c in CONTACT_CARDS}            # noqa: E731
    # the same contact card types, less BCTPARM (no parameter whose meaning and default could be confirmed)
    assert kinds(real) - kinds(ours) == {"BCTPARM"} and kinds(ours) <= kinds(real)
    for b in (ours, real):
        ct = next(iter(b.bctsets.values()))
        assert set(ct.sids) | set(ct.tids) == set(b.bsurfs) == set(b.bcrparas)   # every region paired and parametrised
        assert all(d > 0 for d in ct.max_distances)
        for bs in b.bsurfs.values():                                          # element + three grids of one face
            for e, *three in zip(bs.eids, bs.g1s, bs.g2s, bs.g3s):
                _face_of(b, e, three)
        case = _case_lines(path) if b is ours else _case_lines(DATA / "contact_model.bdf")
        assert any(re.fullmatch(rf"BCSET = {ct.csid}", ln) for ln in case)
        res = next(ln for ln in case if ln.startswith("BCRESULTS"))
        assert {"TRACTION", "FORCE", "SEPDIS"} <= set(res[res.index("(") + 1:res.index(")")].split(","))
        assert any(ln.startswith("SOL 101") or ln == "SOL SESTATIC" for ln in case)

    def bcrpara_fields(text):
        return [ln[8:40] for ln in text.splitlines() if ln.startswith("BCRPARA")]
    # BCRPARA field usage as Femap writes it: CRID, SURF blank, OFFSET 0., TYPE blank
    for f in bcrpara_fields(path.read_text()) + bcrpara_fields((DATA / "contact_model.bdf").read_text()):
        assert f[8:16].strip() == "" and float(f[16:24]) == 0.0 and f[24:32].strip() == ""


def test_friction_variant_writes_fric_and_no_springs(tmp_path):
    _, path = _deck(tmp_path, SMALL + ["contact.friction=0.2", "contact.tangential=friction"])
    bdf = read_bdf(str(path), xref=True, debug=None)
    assert bdf.bctsets[1].frictions == [0.2, 0.0] and "CELAS2" not in bdf.card_count
    _, path = _deck(tmp_path, SMALL + ["contact.stop.side=none"])
    bdf = read_bdf(str(path), xref=True, debug=None)
    assert set(bdf.bsurfs) == {1, 2} and bdf.bctsets[1].sids == [1] and bdf.card_count["CELAS2"] == 24 * 3


# --- issue 23: quadratic skirts (CHEXA 20 / CTETRA 10 / CPENTA 15 with their mid-side grids) ----------------

# Nastran's mid-side grids, edge by edge (QRG CHEXA / CPENTA / CTETRA, 1-based corners), written out here: G9..G20,
# G7..G15, G5..G10. meshio's nastran writer permutes VTK's (= CalculiX's) 20- and 15-node order to these.
NASTRAN_EDGES = {
    20: [(1, 2), (2, 3), (3, 4), (4, 1), (1, 5), (2, 6), (3, 7), (4, 8), (5, 6), (6, 7), (7, 8), (8, 5)],
    15: [(1, 2), (2, 3), (3, 1), (1, 4), (2, 5), (3, 6), (4, 5), (5, 6), (6, 4)],
    10: [(1, 2), (2, 3), (3, 1), (1, 4), (2, 4), (3, 4)],
}
QUAD = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "contact.stop.side=none"]


def _xyz(bdf, ids):
    return np.array([bdf.nodes[int(g)].get_position() for g in ids])


@pytest.mark.parametrize("element, skirt, layer", [("hex20r", "CHEXA", "CHEXA"), ("tet10", "CTETRA", "CPENTA"),
                                                   ("wedge15", "CPENTA", "CPENTA")])
def test_quadratic_solids_in_nastran_order_read_back_with_xref(tmp_path, element, skirt, layer):
    """pyNastran reads the deck with cross-referencing; every solid (skirt and target layer) has its mid-side grids
    at the mid-points of Nastran's edges (within 0.1 of the edge: the skirt's curved edges lie on the true
    cylinder) and a positive Jacobian at every Gauss point once put back in CalculiX order by the importer's
    permutation (node_order_problem); the skirt's cells are the mesh's, grid for grid."""
    from deckbridge.importers.node_order import node_order_problem, to_calculix_order

    model, path = _deck(tmp_path, QUAD + [f"mesh.element={element}"])
    mesh = build_mesh(model)
    bdf = read_bdf(str(path), xref=True, debug=None)
    kinds = {(e.type, e.pid, len(e.node_ids)) for e in bdf.elements.values() if e.type in ("CHEXA", "CPENTA", "CTETRA")}
    n = mesh.hexes.shape[1]
    assert kinds == {(skirt, 1, n), (layer, 2, 20 if layer == "CHEXA" else 15)}
    for e in bdf.elements.values():
        if e.type not in ("CHEXA", "CPENTA", "CTETRA"):
            continue
        x = _xyz(bdf, e.node_ids)
        k = len(e.node_ids)
        nc = k - len(NASTRAN_EDGES[k])
        for m, (a, b) in enumerate(NASTRAN_EDGES[k]):
            off = np.linalg.norm(x[nc + m] - (x[a - 1] + x[b - 1]) / 2)
            assert off <= 0.1 * np.linalg.norm(x[a - 1] - x[b - 1]), (e.eid, nc + m + 1, a, b)
    for pid, name in ((1, mesh.element), (2, {"CHEXA": "c3d20", "CPENTA": "c3d15"}[layer])):
        cells = [e for e in bdf.elements.values() if getattr(e, "pid", None) == pid and e.type in (skirt, layer)]
        ids = sorted({g for e in cells for g in e.node_ids})
        row = {g: i for i, g in enumerate(ids)}
        conn = to_calculix_order(cells[0].type, np.array([[row[g] for g in e.node_ids] for e in cells]))
        assert node_order_problem(_xyz(bdf, ids), conn, name) is None
        if pid == 1:
            assert np.array_equal(np.array([ids[i] for i in conn.ravel()]).reshape(conn.shape) - 1, mesh.hexes)


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_quadratic_bsurfs_name_faces_by_corner_grids_and_meet_their_targets(tmp_path, element):
    """BSURFS source: element + three corner grids (not mid-side) of a face at z = 0; the faces' corners and the
    mid-sides of their edges (Nastran's edge table) are exactly the table's slave nodes; each target face (corners
    and mid-sides of the layer cell's near face) sits on its source face's grid positions (clearance 0)."""
    model, path = _deck(tmp_path, QUAD + [f"mesh.element={element}"])
    mesh = build_mesh(model)
    bdf = read_bdf(str(path), xref=True, debug=None)

    def face(eid, three):
        e = bdf.elements[eid]
        k = len(e.node_ids)
        nc = k - len(NASTRAN_EDGES[k])
        corners = [g for g in e.node_ids[:nc] if g in three or abs(bdf.nodes[g].get_position()[2] -
                                                                    bdf.nodes[three[0]].get_position()[2]) < 1e-12]
        assert set(three) <= set(e.node_ids[:nc])                               # three corner grids
        mids = [e.node_ids[nc + m] for m, (a, b) in enumerate(NASTRAN_EDGES[k])
                if e.node_ids[a - 1] in corners and e.node_ids[b - 1] in corners]
        assert len(corners) in (3, 4) and len(mids) == len(corners)
        return corners, mids

    covered, src_pos = set(), []
    for eid, *three in zip(bdf.bsurfs[1].eids, bdf.bsurfs[1].g1s, bdf.bsurfs[1].g2s, bdf.bsurfs[1].g3s):
        c, m = face(eid, three)
        x = _xyz(bdf, c + m)
        np.testing.assert_allclose(x[:, 2], 0.0, atol=1e-12)
        covered |= set(c + m)
        src_pos.append(sorted(map(tuple, np.round(x, 9))))
    assert covered == set((mesh.table.nodes + 1).tolist())
    tgt_pos = []
    for eid, *three in zip(bdf.bsurfs[2].eids, bdf.bsurfs[2].g1s, bdf.bsurfs[2].g2s, bdf.bsurfs[2].g3s):
        c, m = face(eid, three)
        tgt_pos.append(sorted(map(tuple, np.round(_xyz(bdf, c + m), 9))))
    assert sorted(src_pos) == sorted(tgt_pos)


@needs_data
def test_quadratic_deck_keeps_the_real_simcenter_layout(tmp_path):
    """The same contact cards as the Femap-written Simcenter deck (less BCTPARM), every BSURFS entry three grids of
    one face of its element by pyNastran's own face table, in both decks (the real one: 8-node CHEXA)."""
    _, path = _deck(tmp_path, QUAD + ["mesh.element=hex20"])
    ours = read_bdf(str(path), xref=True, debug=None)
    real = read_bdf(str(DATA / "contact_model.bdf"), xref=True, debug=None)
    kinds = lambda b: {c for c in b.card_count if c in CONTACT_CARDS}            # noqa: E731
    assert kinds(real) - kinds(ours) == {"BCTPARM"} and kinds(ours) <= kinds(real)
    for b in (ours, real):
        for bs in b.bsurfs.values():
            for e, *three in zip(bs.eids, bs.g1s, bs.g2s, bs.g3s):
                _face_of(b, e, three)
    assert "BCTPARM" not in path.read_text().split("BEGIN BULK")[1]


def test_quadratic_refusals_name_the_surface_contact_deck(tmp_path):
    """CGAP on 8-/6-node faces stays refused, in one line naming nastran_surface; the surface-contact deck with
    the radial stop on a tet10 skirt is refused in one line too (not written yet)."""
    from deckbridge.errors import DeckUnsupported
    from deckbridge.render import render_all

    model = load(None, QUAD + ["mesh.element=hex20r"])
    with pytest.raises(DeckUnsupported, match=r"CGAP gaps\) opens the corner nodes .*use the nastran_surface "
                                              r"dialect \(Simcenter surface contact, BSURFS\)") as err:
        render_all(model, tmp_path / "a", names=["nastran"])
    assert "\n" not in str(err.value)
    model = load(None, QUAD[:-1] + ["mesh.element=tet10"])
    with pytest.raises(DeckUnsupported, match=r"radial stop on a tetrahedral skirt's wall faces is not written yet: "
                                              r"set contact.stop.side: none") as err:
        render_all(model, tmp_path / "b", names=["nastran_surface"])
    assert "\n" not in str(err.value) and not any((tmp_path / "b").glob("*.bdf"))


@pytest.mark.parametrize("element", ["hex20r", "tet10"])
def test_reader_places_the_quadratic_decks_grids(tmp_path, element):
    """The OP2 reader's geometry path on a quadratic deck: region 1's grids are the table's slave nodes, corners and
    mid-sides, at the mesh's positions with vertical normals; shares NaN (the corner rule does not hold)."""
    model, path = _deck(tmp_path, QUAD + [f"mesh.element={element}"])
    mesh = build_mesh(model)
    sf = source_faces(path)
    grids = {n for r, n in sf.share if r == 1}
    assert grids == set((mesh.table.nodes + 1).tolist())
    for n in grids:
        np.testing.assert_allclose(sf.xyz[n], mesh.nodes[n - 1], atol=1e-12)
        assert abs(sf.normal[1, n][2]) > 0.99 and np.isnan(sf.share[1, n])
    assert {len(f) for _, f in sf.faces} == ({8} if element == "hex20r" else {6})


@pytest.mark.parametrize("element, side", [("hex20r", "inner"), ("wedge15", "outer")])
def test_quadratic_stop_faces_and_their_targets(tmp_path, element, side):
    """With the radial stop on a 20-node / 15-node skirt: region 3 = the first row's 8-node wall faces on the stop's
    side (corner triples of CHEXA 20 / CPENTA 15 wall faces; horizontal), holding every stop slave node; region 4 =
    20-node CHEXA layer faces whose corners and mid-sides lie on the stop radius (clearance 0: the wall's radius,
    the true cylinder), every mid-side grid at its Nastran edge's mid-point."""
    model, path = _deck(tmp_path, QUAD[:-1] + [f"mesh.element={element}", f"contact.stop.side={side}"])
    mesh = build_mesh(model)
    bdf = read_bdf(str(path), xref=True, debug=None)
    g = model.geometry
    r_wall = g.radius + (g.thickness / 2 if side == "outer" else -g.thickness / 2)
    assert bdf.bctsets[1].sids == [1, 3] and bdf.bctsets[1].tids == [2, 4]

    def face(eid, three):
        e = bdf.elements[eid]
        k = len(e.node_ids)
        nc = k - len(NASTRAN_EDGES[k])
        x = _xyz(bdf, e.node_ids)
        for m, (a, b) in enumerate(NASTRAN_EDGES[k]):
            assert np.linalg.norm(x[nc + m] - (x[a - 1] + x[b - 1]) / 2) <= 0.1 * np.linalg.norm(x[a - 1] - x[b - 1])
        assert set(three) <= set(e.node_ids[:nc])
        r = np.hypot(x[:nc, 0], x[:nc, 1])
        corners = [gid for gid, ri in zip(e.node_ids[:nc], r) if abs(ri - r_wall) < 1e-9]
        mids = [e.node_ids[nc + m] for m, (a, b) in enumerate(NASTRAN_EDGES[k])
                if e.node_ids[a - 1] in corners and e.node_ids[b - 1] in corners]
        assert len(corners) == 4 and len(mids) == 4 and set(three) <= set(corners)
        return corners + mids

    covered = set()
    for eid, *three in zip(bdf.bsurfs[3].eids, bdf.bsurfs[3].g1s, bdf.bsurfs[3].g2s, bdf.bsurfs[3].g3s):
        covered |= set(face(eid, three))
    assert set((mesh.stop.nodes + 1).tolist()) <= covered
    for eid, *three in zip(bdf.bsurfs[4].eids, bdf.bsurfs[4].g1s, bdf.bsurfs[4].g2s, bdf.bsurfs[4].g3s):
        assert bdf.elements[eid].type == "CHEXA" and len(bdf.elements[eid].node_ids) == 20
        x = _xyz(bdf, face(eid, three))
        np.testing.assert_allclose(np.hypot(x[:, 0], x[:, 1]), r_wall, rtol=1e-12)
    assert min(e.Volume() for e in bdf.elements.values() if e.type in ("CHEXA", "CPENTA")) > 0
