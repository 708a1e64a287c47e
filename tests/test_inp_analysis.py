"""Issue 10, inp family: one analysis in every Abaqus/CalculiX deck (NLGEOM, increments, stress output, units,
stiffness comments), checked on the deck text and by ccx 2.20 runs."""

import re
import shutil

import numpy as np
import pandas as pd
import pytest

from deckbridge.errors import DeckUnsupported
from deckbridge.dialects.calculix.runner import run
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.dialects.calculix.numbering import ccx_n2f_groups, ccx_node_slave_areas
from deckbridge.dialects.calculix import reader as reader
from deckbridge.dialects.calculix.el_stress import read_base_wall
from deckbridge.render import render_all

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1"]


def _decks(tmp_path, overrides=(), names=("abaqus", "calculix")):
    model = load(None, SMALL + list(overrides))
    paths = render_all(model, tmp_path, list(names))
    return model, {p.name: p.read_text() for p in paths}


def _step_lines(text):
    return [ln for ln in text.splitlines() if ln.startswith("*STEP")]


def test_nlgeom_false_every_deck_is_geometrically_linear_stop_included(tmp_path):
    """Issue 21.4: the mortar deck's GAPUNI stop no longer switches that deck to NLGEOM."""
    model, decks = _decks(tmp_path / "stop")
    assert all("NLGEOM=NO" in ln for ln in _step_lines(decks["JAR_lagrange.inp"]))
    assert not any("NLGEOM" in ln for ln in _step_lines(decks["JAR_ccx_penalty.inp"]))
    assert "TYPE=GAPUNI" not in decks["JAR_ccx_penalty.inp"]                 # node-to-surface LINEAR
    mortar = decks["JAR_ccx_lagrange.inp"]
    assert "TYPE=GAPUNI" in mortar                                         # its stop is GAPUNI gaps
    steps = _step_lines(mortar)
    assert len(steps) == 2 and not any("NLGEOM" in ln for ln in steps)
    assert "** Geometry: geometrically linear (no NLGEOM), as analysis.nlgeom = false asks." in mortar
    assert "NLGEOM although" not in mortar
    _, free = _decks(tmp_path / "free", ["contact.stop.side=none"])
    assert not any("NLGEOM" in ln for name in ("JAR_ccx_penalty.inp", "JAR_ccx_lagrange.inp")
                   for ln in _step_lines(free[name]))


def test_nlgeom_true_every_deck_carries_it(tmp_path):
    _, decks = _decks(tmp_path, ["analysis.nlgeom=true"])
    assert all("NLGEOM=YES" in ln for ln in _step_lines(decks["JAR_lagrange.inp"]))
    for name in ("JAR_ccx_penalty.inp", "JAR_ccx_lagrange.inp"):
        steps = _step_lines(decks[name])
        assert len(steps) == 2 and all(ln.startswith("*STEP, NLGEOM, INC=") for ln in steps), name
    assert "TYPE=GAPUNI" in decks["JAR_ccx_penalty.inp"]


def test_node_to_surface_slopes_reproduce_each_node_k_c(tmp_path):
    """slope x A_ccx = k_c for every slave node (table and stop); one group per radial position."""
    model, decks = _decks(tmp_path, names=("calculix",))
    mesh = build_mesh(model)
    text = decks["JAR_ccx_penalty.inp"]
    blocks = re.findall(r"\*SURFACE, NAME=SLAVE_(TABLE|STOP)\d+, TYPE=NODE\n((?:\d+\n)+)\*CONTACT PAIR.*\n.*\n"
                        r"\*SURFACE INTERACTION.*\n\*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR\n(\S+), (\S+)\n", text)
    assert len(blocks) == (mesh.n_r + 1) + 1                                # inner/outer table rows + stop
    a = ccx_node_slave_areas(mesh)
    seen = set()
    for surface, nodes, slope, sigma_inf in blocks:
        ss = mesh.table if surface == "TABLE" else mesh.stop
        k = dict(zip(ss.nodes + 1, ss.k))
        for n in map(int, nodes.split()):
            assert float(slope.rstrip(",")) * a[n - 1] == pytest.approx(k[n], rel=1e-11)
            seen.add((surface, n))
        assert float(sigma_inf) == pytest.approx(mesh.k_open_ratio * float(slope.rstrip(",")) * model.geometry.thickness)
    assert len(seen) == mesh.table.nodes.size + mesh.stop.nodes.size


def test_ccx_area_of_a_node_is_a_quarter_of_its_free_faces():
    """Closed form on the 16 x 4 x 1 mesh: inner base node = base trapezoid / 2 + chord x h1 / 2."""
    model = load(None, SMALL)
    mesh = build_mesh(model)
    g = model.geometry
    s, c = np.sin(np.pi / 16), np.cos(np.pi / 16)
    ci, co = 2 * (g.radius - g.thickness / 2) * s, 2 * (g.radius + g.thickness / 2) * s
    base = (ci + co) / 2 * g.thickness * c
    a = ccx_node_slave_areas(mesh)
    assert a[0] == pytest.approx(base / 2 + ci * g.height / 4 / 2, rel=1e-12)
    assert a[16] == pytest.approx(base / 2 + co * g.height / 4 / 2, rel=1e-12)
    assert len(ccx_n2f_groups(mesh)) == 3


def test_friction_is_refused_by_calculix_before_writing_and_rendered_by_abaqus(tmp_path):
    model = load(None, SMALL + ["contact.friction=0.2"])
    with pytest.raises(DeckUnsupported) as err:
        render_all(model, tmp_path / "out", ["abaqus", "calculix"])
    assert err.value.dialect == "calculix" and "contact.friction = 0.2" in err.value.reason
    assert "\n" not in str(err.value)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())
    deck = render_all(model, tmp_path / "abq", ["abaqus"])[0]
    assert deck.read_text().count("*FRICTION, LAGRANGE") == 1            # the table's; the stop is frictionless
    from deckbridge.importers.inp_mesh import contact_friction
    assert sorted(mu for _, _, mu in contact_friction(deck)) == [0.0, 0.2]


def test_comments_stiffness_ratio_units_inc_and_clean_numbers(tmp_path):
    _, decks = _decks(tmp_path, ["steps.increments=1500"])
    for name, text in decks.items():
        assert "** deckbridge-units: SI" in text and "N, m, Pa" in text, name
        m = re.search(r"KA / \(E A / h1\) = (\S+) \.\. ([^:\s]+):", text)
        assert m and 0.05 < float(m.group(1)) <= float(m.group(2)) < 0.12, name     # alpha 0.1 -> ~0.08
        assert "alpha = 0.1" in text and "N/m" in text
        assert all("INC=15000" in ln for ln in _step_lines(text)), name
        assert "*ELSET, ELSET=EBASE" in text and text.count("*EL PRINT, ELSET=EBASE") == 2
        data = [ln for ln in text.splitlines() if not ln.startswith("*")]
        residues = [t for ln in data for t in re.findall(r"[-+]?\d\.\d+e-(\d+)", ln) if int(t) >= 15]
        assert not residues, (name, residues[:3])


@needs_ccx
def test_1500_increments_run_to_the_end_in_ccx(tmp_path):
    """steps.increments = 1500 (INC = 15000 from the model): ccx runs every increment. Output requests other
    than the contact print are dropped to keep the run short (measured ~11 s on 8 x 1 x 1, 2-core box)."""
    model = load(None, ["mesh.n_theta=8", "mesh.n_z=1", "mesh.n_r=1", "steps.increments=1500",
                        "steps.lambda_max=0.1", "contact.stop.side=none"])
    deck = render_all(model, tmp_path, ["calculix"])[0]
    text = re.sub(r"(?m)^\*(EL PRINT|NODE FILE|NODE PRINT)[^\n]*\n[^\n]*\n", "", deck.read_text())
    deck.write_text(text)
    done = run(deck, timeout_s=120)
    assert done.increments == 1 + 1500


@needs_ccx
def test_mm_and_si_decks_read_back_the_same(tmp_path):
    """Both CalculiX decks in N, mm, MPa and in SI, run by ccx: the same sigma_N, gaps and base wall stresses
    after reading back, to 1e-6 relative (of the peak)."""
    out = {}
    for units in ("SI", "mm"):
        model = load(None, ["mesh.n_theta=12", "mesh.n_z=3", "mesh.n_r=1", "units=" + units])
        folder = tmp_path / units
        for p in render_all(model, folder, ["calculix"]):
            run(p, timeout_s=120)
        out[units] = (reader.read(folder, model=model), {m: read_base_wall(folder / f"JAR_ccx_{m}.dat", model)
                                                          for m in ("penalty", "lagrange")})
    text = (tmp_path / "mm" / "JAR_ccx_penalty.inp").read_text()
    assert "** deckbridge-units: mm" in text and "N, mm, MPa" in text
    si, mm = out["SI"][0], out["mm"][0]
    assert len(si) == len(mm) and (si.node.to_numpy() == mm.node.to_numpy()).all()
    for col in ("sigma_n_pa", "gap_m"):
        peak = np.nanmax(np.abs(si[col]))
        assert np.nanmax(np.abs(si[col] - mm[col])) < 1e-6 * peak, col
    assert (si.status == mm.status).all()
    for m in ("penalty", "lagrange"):
        a, b = out["SI"][1][m], out["mm"][1][m]
        pd.testing.assert_frame_equal(a, b, check_exact=False, rtol=1e-6, atol=1e-6 * a.szz_mean_pa.abs().max())
