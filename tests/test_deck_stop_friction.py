"""The radial stop is frictionless in every deck (issue 21 item 6) and ``decks`` leaves out a deck that cannot
carry the model with a note, as ``run`` does (issue 21 item 16).

The decks are read back by their parsers (pyNastran for the .bdf, :func:`deckbridge.importers.inp_mesh.contact_friction`
for the .inp) and the stop is told from the table by geometry, not by the renderer's numbering: a table gap's
axis GA -> GB is vertical, a stop gap's is radial.
"""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner
from pyNastran.bdf.bdf import BDF

from deckbridge.cli import main
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.importers.inp_mesh import contact_friction
from deckbridge.dialects.abaqus import render as abaqus
from deckbridge.dialects.calculix import render as calculix
from deckbridge.dialects.nastran import render as nastran

MU = 0.2
SMALL = ["mesh.n_theta=12", "mesh.n_z=3", "mesh.n_r=1", f"contact.friction={MU}"]


def _model(tangential):
    model = load(None, SMALL + [f"contact.tangential={tangential}"])
    assert model.contact.stop.side != "none"
    return model, build_mesh(model)


@pytest.mark.parametrize("tangential", ["springs", "friction"])
def test_nastran_stop_pgaps_frictionless(tmp_path, tangential):
    model, mesh = _model(tangential)
    (path,) = nastran.write(model, mesh, tmp_path)
    bdf = BDF(debug=None)
    bdf.read_bdf(str(path), xref=False)
    kinds = {"table": [], "stop": []}
    for eid, gap in bdf.elements.items():
        if gap.type != "CGAP":
            continue
        a, b = (np.asarray(bdf.nodes[n].xyz, float) for n in gap.node_ids)
        axis = (b - a) / np.linalg.norm(b - a)
        kinds["table" if abs(axis[2]) > 0.99 else "stop"].append(bdf.properties[gap.pid])
    assert len(kinds["stop"]) == model.mesh.n_theta and kinds["table"]
    for p in kinds["stop"]:
        assert (p.mu1, p.mu2, p.kt) == (0.0, 0.0, 0.0), (p.pid, p.mu1, p.mu2, p.kt)
    # the table keeps the model's friction (the read-back sees the value the stop must not get)
    assert {(p.mu1, p.mu2) for p in kinds["table"]} == {(MU, MU)}
    assert all((p.kt > 0) == (tangential == "friction") for p in kinds["table"])


@pytest.mark.parametrize("tangential", ["springs", "friction"])
def test_abaqus_stop_interaction_frictionless(tmp_path, tangential):
    model, mesh = _model(tangential)
    path = abaqus.write(model, mesh, tmp_path)[0]          # the Lagrange deck (the augmented one: same pairs)
    mu = {(s, m): f for s, m, f in contact_friction(path)}
    assert mu == {("SLAVE_TABLE", "MASTER_TABLE"): MU, ("SLAVE_STOP", "MASTER_STOP"): 0.0}


def test_calculix_stop_frictionless(tmp_path):
    model, mesh = _model("friction")
    paths = calculix.write(model, mesh, tmp_path)
    pen = contact_friction(paths[0])
    assert {m for _, m, _ in pen} == {"MASTER_TABLE", "MASTER_STOP"}
    assert {f for _, m, f in pen if m == "MASTER_STOP"} == {0.0}
    assert {f for _, m, f in pen if m == "MASTER_TABLE"} == {MU}
    # mortar: the table pair only (its stop is not a contact pair)
    assert {(m, f) for _, m, f in contact_friction(paths[1])} == {("MASTER_TABLE", MU)}
    # face-to-face: the table pair(s) only, its stop is GAPUNI gaps
    assert {(m, f) for _, m, f in contact_friction(paths[2])} == {("MASTER_TABLE", MU)}


def test_decks_leaves_out_mystran_with_friction(tmp_path):
    """``decks`` as ``run``: the MYSTRAN deck (no friction) is left out with a note, the others are written."""
    out = tmp_path / "d"
    res = CliRunner().invoke(main, ["decks", "--set", "mesh.n_theta=12", "--set", "mesh.n_z=3", "--set",
                                    f"contact.friction={MU}", "--set", "contact.tangential=friction",
                                    "-o", str(out)])
    assert res.exit_code == 0, res.output
    assert "note: mystran deck: contact.tangential = friction" in res.output
    names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == ["JAR_augmented.inp", "JAR_ccx_f2f.inp", "JAR_ccx_lagrange.inp", "JAR_ccx_penalty.inp",
                     "JAR_lagrange.inp", "JAR_model.vtu", "JAR_penalty.bdf", "JAR_surface.bdf"]
    # naming the dialect that cannot carry the model is a one-line refusal, nothing written
    res = CliRunner().invoke(main, ["decks", "--set", f"contact.friction={MU}", "--set",
                                    "contact.tangential=friction", "--dialect", "mystran", "-o",
                                    str(tmp_path / "e")])
    assert res.exit_code == 2 and "mystran deck" in res.output and not (tmp_path / "e").exists()
