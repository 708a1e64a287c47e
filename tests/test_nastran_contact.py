"""Nastran surface-contact OP2 reader on a real Simcenter SOL 101 run (../shared/data/nx_surface_contact).

Independent truths: pyNastran's own OQGCF1 / OSPDS parsers (another reader of the same records), face
areas from pyNastran's CHEXA face geometry, the force balance of each contact region, and the outward
normal of the source faces (compression pushes into the source body).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from deckbridge import read_contact
from deckbridge.errors import DeckbridgeError
from deckbridge.readers import detect, read
from deckbridge.dialects.nastran_surface.reader import contact_tables

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "nx_surface_contact"
OP2, BDF = DATA / "contact_model.op2", DATA / "contact_model.bdf"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"shared Simcenter surface-contact model absent ({DATA})")
MSC = Path(__file__).resolve().parents[2] / "shared" / "data" / "msc_gap_examples" / "v10601s.op2"


@pytest.fixture(scope="module")
def raw():
    return contact_tables(OP2)


@pytest.fixture(scope="module")
def bdf():
    from pyNastran.bdf.bdf import read_bdf
    return read_bdf(str(BDF), xref=True, debug=None)


def _region_faces(bdf, rid):
    """(grids of the face, its area, outward unit normal) of each BSURFS face of region ``rid``, by pyNastran."""
    out = []
    bs = bdf.bsurfs[rid]
    for eid, g1, g2, g3 in zip(bs.eids, bs.g1s, bs.g2s, bs.g3s):
        el = bdf.elements[eid]
        face = next(f for f in el.faces.values() if {g1, g2, g3} <= set(f))
        x = np.array([bdf.nodes[g].get_position() for g in face])
        area = 0.5 * np.linalg.norm(np.cross(x[2] - x[0], x[3] - x[1]))      # quad area from its diagonals
        n = np.cross(x[2] - x[0], x[3] - x[1])
        n /= np.linalg.norm(n)
        centroid = np.mean([bdf.nodes[g].get_position() for g in el.node_ids], axis=0)
        out.append((tuple(face), area, n if n @ (x.mean(0) - centroid) > 0 else -n))
    return out


@needs_data
def test_tables_match_pynastran_where_it_reads_them(raw):
    from pyNastran.op2.op2 import read_op2
    op2 = read_op2(str(OP2), debug=None, log=None)
    f = op2.contact_forces[1]
    mine = raw.set_index("node").loc[f.node_gridtype[:, 0]]
    np.testing.assert_array_equal(mine[["fx", "fy", "fz", "mx", "my", "mz"]].to_numpy(), f.data[0].astype(float))
    for tab, col in ((op2.separation_final[1], "separation"), (op2.separation_initial[1], "separation_initial")):
        np.testing.assert_array_equal(raw.set_index("node").loc[tab.node, col].to_numpy(), tab.data[0, :, 0])
    assert len(raw) == 240 and raw["separation"].notna().sum() == 120
    # pyNastran 1.4.1 stores OBC1 as zeros; where a later version stores it, it must agree with ours
    p = op2.contact_tractions_and_pressure[1]
    assert (raw["pressure"] > 0).sum() == 24 and (raw["pressure"] >= 0).all()
    if np.any(p.data != 0):
        np.testing.assert_array_equal(raw.set_index("node").loc[p.node_gridtype[:, 0], "pressure"], p.data[0, :, 0])


@needs_data
@pytest.mark.parametrize("rid", [1, 2, 3, 4])
def test_region_force_is_pressure_times_face_share(raw, bdf, rid):
    """Per contact region, |sum of OQGCF1 forces| = sum of grid pressure x the grid's share of the region's
    faces (a quarter of each rectangular face, areas by pyNastran), to float32 precision."""
    faces = _region_faces(bdf, rid)
    share = {}
    for grids, area, _ in faces:
        for g in grids:
            share[g] = share.get(g, 0.0) + area / 4.0
    t = raw.set_index("node").loc[sorted(share)]
    force = t[["fx", "fy", "fz"]].to_numpy().sum(axis=0)
    from_pressure = float((t["pressure"] * t.index.map(share)).sum())
    assert np.linalg.norm(force) == pytest.approx(from_pressure, rel=1e-6, abs=1e-3)
    assert from_pressure > 3000.0 or rid in (1, 2)          # regions 3/4 touch, 1/2 stay open here
    # compression: the source side's force pushes into its own body (against the outward normal)
    if rid == 3:
        n_out = np.mean([n for _, _, n in faces], axis=0)
        assert force @ n_out < -0.99 * np.linalg.norm(force)


@needs_data
def test_tidy_table_signs_status_and_total_force(raw, bdf):
    df = read_contact(OP2)
    assert set(df["node"]) == {g for rid in (2, 3) for f in _region_faces(bdf, rid) for g in f[0]}
    assert (df["sigma_n_pa"] <= 0).all() and (df["sigma_n_pa"] < 0).sum() == 12
    closed = df["status"] == "closed"
    assert (df.loc[~closed, "sigma_n_pa"] == 0).all()       # no pressure where open
    assert (df.loc[closed, "sigma_n_pa"] < 0).all()
    assert (df.loc[df["gap_m"] <= 0, "status"] == "closed").all()   # a penetrating grid is closed
    src3 = raw.set_index("node").loc[sorted({g for f in _region_faces(bdf, 3) for g in f[0]})]
    total = np.linalg.norm(src3[["fx", "fy", "fz"]].to_numpy().sum(axis=0))
    assert df["force_n"].sum() == pytest.approx(total, rel=1e-6)
    np.testing.assert_allclose(df["sigma_n_pa"], -df["force_n"] / df["area_m2"], rtol=1e-12)
    assert set(df["surface"]) == {"stop"}                   # the blocks touch along x: horizontal normals


@needs_data
def test_reachable_from_the_reader_registry(tmp_path):
    assert detect(OP2) == "nastran_contact"
    df = read(OP2)
    assert len(df) == 120 and df["source"].iloc[0] == "nastran_surface"
    if MSC.is_file():
        assert detect(MSC) == "nastran_op2"                 # a CGAP OP2 stays with the gap reader


def _copy(tmp_path, data: bytes) -> Path:
    shutil.copy(BDF, tmp_path / "m.bdf")
    (tmp_path / "m.op2").write_bytes(data)
    return tmp_path / "m.op2"


@needs_data
@pytest.mark.parametrize("cut", [20000, 32600, 41140 - 3, 41140 - 12])
def test_truncated_copies_are_one_line_errors(tmp_path, cut):
    data = OP2.read_bytes()
    p = _copy(tmp_path, data[:cut])
    with pytest.raises(DeckbridgeError, match="truncated|end-of-file|cut") as e:
        read_contact(p)
    assert "\n" not in str(e.value) and "m.op2" in str(e.value)


@needs_data
def test_garbled_and_non_finite_copies(tmp_path):
    data = bytearray(OP2.read_bytes())
    bad = bytearray(data)
    bad[32560 + 4 + 4800] ^= 0x01                         # the OBC1 data record's closing length word
    with pytest.raises(DeckbridgeError, match="garbled") as e:
        read_contact(_copy(tmp_path, bytes(bad)))
    assert "\n" not in str(e.value)
    nan = bytearray(data)
    k = 32564 + 4 * 5 * 12 + 4               # OBC1 entry 13 (grid 37), its pressure word
    assert int.from_bytes(nan[k - 4:k], "little") == 370 + 1
    nan[k:k + 4] = np.float32(np.nan).tobytes()
    with pytest.raises(DeckbridgeError, match="non-finite"):
        read_contact(_copy(tmp_path, bytes(nan)))


@needs_data
def test_op2_without_contact_tables(tmp_path):
    if not MSC.is_file():
        pytest.skip(f"shared MSC gap examples absent ({MSC})")
    with pytest.raises(DeckbridgeError, match="no contact result tables") as e:
        read_contact(MSC)
    assert "\n" not in str(e.value)


@needs_data
def test_no_deck_beside_is_one_line(tmp_path):
    p = tmp_path / "alone.op2"
    p.write_bytes(OP2.read_bytes())
    with pytest.raises(DeckbridgeError, match="no deck beside"):
        read_contact(p)
    assert len(read_contact(p, deck=BDF)) == 120


@pytest.mark.parametrize("data, what", [
    (b"", "empty"), (b"ceci n'est pas un op2 " * 4, "not an OP2"),
    ((4).to_bytes(4, "little") + (3).to_bytes(4, "little") + (4).to_bytes(4, "little") + (2 ** 30).to_bytes(4, "little"),
     "truncated"),
])
def test_hostile_files_are_one_line_errors(tmp_path, data, what):
    p = tmp_path / "x.op2"
    p.write_bytes(data)
    (tmp_path / "x.bdf").write_text("BEGIN BULK\nENDDATA\n")
    with pytest.raises(DeckbridgeError, match=what) as e:
        read_contact(p)
    assert "\n" not in str(e.value)
    with pytest.raises(DeckbridgeError):
        read(p)                                   # detected as nothing: format not recognised


def test_units_of_a_deckbridge_deck_beside(tmp_path):
    """A deckbridge mm deck beside the OP2 converts lengths by 1e3 and pressures by 1e-6 (its units line)."""
    from deckbridge.dialects import DIALECTS
    from deckbridge.mesh import build_mesh
    from deckbridge.model import load
    from deckbridge.dialects.nastran_surface.reader import _units
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=3", "mesh.n_r=1", "units=mm"])
    (deck,) = DIALECTS["nastran_surface"].write(model, build_mesh(model), tmp_path)
    u = _units(deck.with_suffix(".op2"), deck, None)
    assert (u.length, u.stress) == (1e3, 1e-6)


@needs_data
def test_grid_pressure_is_the_average_of_its_face_pressures(raw, bdf):
    """Simcenter's grid pressure = mean of the (constant) pressures of the source faces around the grid: the
    face pressures solved from the grid values reproduce them to float32 precision, and a face is loaded
    exactly when one of its grids has separation <= 0 (the reader's status rule)."""
    faces = [f for f, _, _ in _region_faces(bdf, 3)]
    grids = sorted({g for f in faces for g in f})
    a = np.zeros((len(grids), len(faces)))
    for j, f in enumerate(faces):
        for g in f:
            a[grids.index(g), j] = 1.0
    a /= a.sum(axis=1, keepdims=True)
    t = raw.set_index("node").loc[grids]
    p = t["pressure"].to_numpy()
    face_p, *_ = np.linalg.lstsq(a, p, rcond=None)
    assert np.abs(a @ face_p - p).max() < 1e-5 * p.max()
    touching = np.array([min(t.loc[g, "separation"] for g in f) <= 0 for f in faces])
    assert touching.sum() == 5 and (face_p[touching] > 100).all() and np.abs(face_p[~touching]).max() < 1e-4
