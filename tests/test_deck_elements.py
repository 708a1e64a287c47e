"""Decks right for the skirt's element type (issue 23, deckbridge/deck_elements.py): C3D8 decks against the
reference solver's C3D8 (same mesh, same element), the refusals of node-based dialects on quadratic faces,
the 20-node element cards."""

from __future__ import annotations

import numpy as np
import pytest

from deckbridge.deck_elements import ccx_element_lines
from deckbridge.errors import DeckUnsupported
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.render import render_all
from job_tables import run_job_tables

SMALL = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]


def test_hex8_decks_match_the_reference_c3d8_within_2_percent(tmp_path):
    """Reference C3D8 (2 x 2 x 2 Gauss, no incompatible modes) against ccx C3D8 decks on the same mesh:
    max |d sigma_N| / peak |sigma_N| over the table at every state, past liftoff (lambda 1)."""
    model = load(None, SMALL + ["mesh.element=hex8", "load_introduction=kinematic"])
    run_job_tables(model, tmp_path, with_ccx=True, echo=lambda s: None)
    assert "*ELEMENT, TYPE=C3D8, ELSET=ESKIRT" in (tmp_path / "decks" / "JAR_ccx_lagrange.inp").read_text()
    ccx = read(tmp_path / "ccx", model=model)
    for ref_method, ccx_method in (("lagrange", "mortar"), ("penalty", "penalty")):
        ref = read(tmp_path / f"reference_{ref_method}", model=model)
        c = ccx[ccx.method == ccx_method]
        j = ref[ref.surface == "table"].merge(c[c.surface == "table"], on=["step", "increment", "node"],
                                              suffixes=("_r", "_c"))
        assert len(j) == 11 * 48
        for _, g in j.groupby(["step", "increment"]):
            err = float(np.abs(g.sigma_n_pa_r - g.sigma_n_pa_c).max() / np.abs(g.sigma_n_pa_r).max())
            assert err < 0.02, (ccx_method, float(g.load_factor_r.iloc[0]), err)
    assert (ref[(ref.load_factor == 1.0) & (ref.surface == "table")].status == "open").any()   # past liftoff


@pytest.mark.parametrize("dialect, why", [("nastran", "CGAP"), ("mystran", "CGAP"),
                                          ("calculix", "GAPUNI")])
def test_node_based_dialects_refused_on_quadratic_faces(tmp_path, dialect, why):
    model = load(None, SMALL + ["mesh.element=hex20r"])
    with pytest.raises(DeckUnsupported, match=f"(?i)mesh.element = hex20r: .*{why}.*calculix") as err:
        render_all(model, tmp_path, names=[dialect])
    assert "\n" not in str(err.value)
    assert not any(tmp_path.glob("*.inp")) and not any(tmp_path.glob("*.bdf"))


def test_calculix_writes_the_mortar_and_face_to_face_decks_on_quadratic_faces(tmp_path):
    model = load(None, SMALL + ["mesh.element=tet10", "contact.stop.side=none"])
    files = render_all(model, tmp_path, names=["calculix"])
    assert [f.name for f in files] == ["JAR_ccx_lagrange.inp", "JAR_ccx_f2f.inp"]
    for f, pair in zip(files, ("TYPE=MORTAR", "TYPE=SURFACE TO SURFACE")):
        text = f.read_text()
        assert pair in text and "*ELEMENT, TYPE=C3D10, ELSET=ESKIRT" in text and "GAPUNI" not in text


def test_twenty_node_cards_continue_after_sixteen_entries():
    text = ccx_element_lines([7], [np.arange(1, 21)])
    first, second = text.split("\n")
    assert first == "7, " + ", ".join(map(str, range(1, 16))) + ","
    assert second == ", ".join(map(str, range(16, 21)))
