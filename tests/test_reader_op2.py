"""Nastran OP2 gap reader against real MSC Nastran result files (../shared/data/msc_gap_examples,
values from its README and from the PGAP data of the decks), and the element numbering shared
with the penalty deck."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pyNastran.bdf.bdf import BDF

from deckbridge.errors import DeckbridgeError
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import detect, read
from deckbridge.dialects.nastran.reader import deck_contact_map, model_contact_map, read_gap_forces
from deckbridge.dialects.nastran.render import write

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "msc_gap_examples"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"shared MSC gap examples absent ({DATA})")


@needs_data
def test_v10601s_closed_and_open_gap():
    df = read_gap_forces(DATA / "v10601s.op2")
    assert set(df["table"]) == {"OEF1X", "OESNLXR"}
    for _, tab in df.groupby("table"):
        g = tab.set_index("element")
        assert list(g.index) == [101, 102] and (g["subcase"] == 1).all()
        # gap 101 closed: compression force = KA * closure, KA = 2.9e8 (PGAP 400), U0 = 0
        assert g.loc[101, "axial_u_m"] == pytest.approx(1.1494253e-4, rel=1e-6)
        assert g.loc[101, "force_n"] == pytest.approx(33333.33, rel=1e-6)
        assert g.loc[101, "force_n"] == pytest.approx(2.9e8 * g.loc[101, "axial_u_m"], rel=1e-6)
        assert g.loc[101, "opening_m"] == pytest.approx(-1.1494253e-4, rel=1e-6)
        assert g.loc[101, "status"] == "closed"
        # gap 102 open by 0.5443, no force
        assert g.loc[102, "opening_m"] == pytest.approx(0.54433155, rel=1e-6)
        assert abs(g.loc[102, "force_n"]) < 1e-3 and g.loc[102, "status"] == "open"


@needs_data
def test_v10601s_tidy_without_model():
    assert detect(DATA / "v10601s.op2") == "nastran_op2"
    df = read(DATA / "v10601s.op2").set_index("node")
    # GA grids 5 and 6 from the deck beside the OP2; area 1, so sigma_n is minus the force
    assert list(df.index) == [5, 6]
    assert df.loc[5, "sigma_n_pa"] == pytest.approx(-33333.33, rel=1e-6)
    assert df.loc[5, "status"] == "closed" and df.loc[6, "status"] == "open"
    assert df.loc[6, "gap_m"] == pytest.approx(0.54433155, rel=1e-6)
    assert (df["step"] == 1).all() and (df["load_factor"] == 0).all() and (df["source"] == "nastran").all()


@needs_data
def test_cc188b_preloaded_open_gap_carries_force():
    # PGAP 38: U0 = 0.2061553, F0 = 3.6e5, KA = 349251.3, KB = 1746257 (cc188b.bdf)
    u0, f0, kb = 0.2061553, 360000.0, 1746257.0
    for tab in read_gap_forces(DATA / "cc188b.op2").itertuples():
        assert tab.element == 3801 and tab.u0_m == pytest.approx(u0)
        assert tab.axial_u_m == pytest.approx(0.18888853, rel=1e-6)
        assert tab.opening_m == pytest.approx(u0 - 0.18888853, rel=1e-5) and tab.status == "open"
        assert tab.force_n == pytest.approx(329847.81, rel=1e-6)
        assert tab.force_n == pytest.approx(f0 + kb * (tab.axial_u_m - u0), rel=1e-5)   # open branch
    df = read(DATA / "cc188b.op2")
    assert df["status"].tolist() == ["open"] and df["sigma_n_pa"].iloc[0] == pytest.approx(-329847.81, rel=1e-6)


@needs_data
def test_dbxdra7_linear_force_table():
    df = read_gap_forces(DATA / "dbxdra7.op2", u0=0.254)      # PGAP 1: U0 = .254
    assert sorted(df["element"]) == [1, 21] and set(df["table"]) == {"OEF1X"}
    assert np.allclose(df["axial_u_m"], 0.25072205, rtol=1e-6)
    assert np.allclose(df["opening_m"], 0.254 - 0.25072205, rtol=1e-5) and (df["status"] == "open").all()
    assert np.all(np.abs(df["force_n"]) < 1e-9)
    # its deck uses replication pyNastran cannot read: the tidy reader says so in one line
    with pytest.raises(DeckbridgeError, match="dbxdra7.bdf"):
        read(DATA / "dbxdra7.op2")


def test_not_an_op2(tmp_path):
    bad = tmp_path / "x.op2"
    bad.write_bytes(b"not an op2 file at all")
    with pytest.raises(DeckbridgeError, match="x.op2"):
        read_gap_forces(bad)


def test_gap_ids_map_to_the_deck_nodes(tmp_path):
    """The element -> slave node map used for OP2/F06 results matches the CGAPs of the deck."""
    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "contact.stop.side=outer"])
    mesh = build_mesh(model)
    deck = write(model, mesh, tmp_path)[0]
    bdf = BDF(debug=None)
    bdf.read_bdf(str(deck), xref=True)
    cmap = model_contact_map(model)
    gaps = {e.eid: e for e in bdf.elements.values() if e.type == "CGAP"}
    assert sorted(gaps) == sorted(cmap.index)
    for eid, row in cmap.iterrows():
        e = gaps[eid]
        p = e.ga_ref.get_position()
        assert e.Ga() == row["node"]
        assert np.degrees(np.arctan2(p[1], p[0])) % 360 == pytest.approx(row["theta_deg"], abs=1e-9)
        vertical = abs((e.gb_ref.get_position() - p)[2]) > 0
        assert row["surface"] == ("table" if vertical else "stop")
        # outer stop: master normal points inward, spring DOF +r
        assert row["dof_sign"] == (1 if vertical else -1)
    # the same map read from the deck itself (areas 1)
    dmap = deck_contact_map(deck)
    assert (dmap.loc[cmap.index, "node"].to_numpy() == cmap["node"].to_numpy()).all()
    assert (dmap.loc[cmap.index, "surface"].to_numpy() == cmap["surface"].to_numpy()).all()
    assert (dmap["area"] == 1.0).all()


def test_tidy_with_model_areas_and_load_factors():
    """Forces become stresses through the mesh's tributary areas; SOL 106 load steps stored per
    subcase (0..1) or cumulatively (1..2) give the same load factor."""
    import pandas as pd

    from deckbridge.dialects.nastran.reader import tidy
    from deckbridge.numbering.nastran import gap_layout

    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.lambda_max=1.6"])
    lay = gap_layout(build_mesh(model))
    e_tab, e_stop = int(lay.eid[0]), int(lay.eid[-1])
    raw = pd.DataFrame({"element": [e_tab, e_stop, e_tab], "subcase": [1, 2, 2], "increment": [1, 5, 5],
                        "time": [1.0, 0.5, 1.5], "force_n": [1000.0, 2000.0, 0.0],
                        "axial_u_m": [1e-6, 2e-6, -3e-6]})
    df = tidy(raw, model_contact_map(model), Path("x.op2"), "nastran", "penalty", model.steps.lambda_max)
    assert df["surface"].tolist() == ["table", "stop", "table"]
    assert df["node"].tolist() == [int(lay.node[0]), int(lay.node[-1]), int(lay.node[0])]
    np.testing.assert_allclose(df["sigma_n_pa"], [-1000.0 / lay.area[0], -2000.0 / lay.area[-1], 0.0])
    np.testing.assert_allclose(df["load_factor"], [0.0, 0.8, 0.8])
    np.testing.assert_allclose(df["gap_m"], [-1e-6, -2e-6, 3e-6])
    assert df["status"].tolist() == ["closed", "closed", "open"]


def test_deck_units_line_converts_the_deck_map_to_si(tmp_path):
    """A deck written in mm says so in its header; the element map read from it is in metres and
    equals the model's map (areas aside)."""
    from deckbridge.dialects.nastran.reader import deck_units, result_units

    model = load(None, ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "units=mm", "contact.stop.radius=1.485"])
    deck = write(model, build_mesh(model), tmp_path)[0]
    assert deck_units(deck) == "mm"
    op2 = deck.with_suffix(".op2")
    assert result_units(op2, None).length == 1e3                      # the deck beside the results wins
    assert result_units(tmp_path / "elsewhere" / "x.op2", model).length == 1e3
    assert result_units(tmp_path / "elsewhere" / "x.op2", None).length == 1.0
    dmap, cmap = deck_contact_map(deck), model_contact_map(model)
    for col in ("r", "z", "u0", "theta_deg"):
        np.testing.assert_allclose(dmap.loc[cmap.index, col], cmap[col], rtol=1e-12, atol=1e-12, err_msg=col)
    assert cmap["u0"].max() == pytest.approx(0.005, rel=1e-9)
