"""Quadratic skirts off the default path (issue 23): units mm against SI, friction, reading results back.

- units: the model is SI whatever its ``units`` (the deck units), so the reference results must not change; the
  decks (CalculiX mortar and face-to-face, Abaqus, Nastran surface) must carry every number converted; what ccx
  computes in mm must read back as the SI run (to ccx's printed digits);
- friction on 8-/6-node faces with the radial stop: refused in one line naming the key;
- the reference's own face-penalty folder of a quadratic skirt reads back through the contact-law check.
Set-up and helpers: tests/test_quadratic_offpath.py.
"""

import numpy as np
import pytest

from test_quadratic_offpath import METHODS, R, _model, _solve

# ---- units: mm against SI --------------------------------------------------------------------------------------
# The model is SI whatever its ``units`` (the deck units): the reference results must not change, the decks must
# carry every number converted (1 m = 1e3 mm, 1 Pa = 1e-6 MPa (N/mm^2), 1 N m = 1e3 N mm, 1 N/m = 1e-3 N/mm,
# a pressure-overclosure slope 1 Pa/m = 1e-9 MPa/mm), and what ccx computes in mm must read back as the SI run.
MM = {"length": 1e3, "stress": 1e-6, "force": 1.0, "moment": 1e3, "stiffness": 1e-3, "slope": 1e-9}


def test_units_mm_reference_results_equal_si():
    """The tet10 thin wall (t/R 0.005, 48 x 8 x 1, tests/test_quadratic_offpath.py's set-up) solved with units: SI
    and mm: every column of both methods' contact tables and the onsets equal to 1e-9 of the column's largest."""
    m = _model("tet10", 0.005, 48, 8, 1)
    res, _ = _solve(m)
    mm = m.with_overrides({"units": "mm"})
    assert mm.units == "mm"
    res_mm, _ = _solve(mm)
    for method in METHODS:
        a, b = res[method][0], res_mm[method][0]
        assert len(a) == len(b) and list(a.columns) == list(b.columns)
        for col in a.columns:
            if a[col].dtype.kind == "f":
                scale = max(float(np.abs(a[col]).max()), 1e-300)
                assert np.abs(a[col].to_numpy() - b[col].to_numpy()).max() <= 1e-9 * scale, (method, col)
            else:
                assert (a[col].to_numpy() == b[col].to_numpy()).all(), (method, col)
        assert res_mm[method][2].liftoff_load_factor == pytest.approx(res[method][2].liftoff_load_factor, rel=1e-9)


_NUM = r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?"


def _inp_cards(path):
    """[(keyword, data fields as floats)] of an inp deck's data lines (comments left out)."""
    import re
    out, kw = [], None
    for line in path.read_text().splitlines():
        if line.startswith("**"):
            continue
        if line.startswith("*"):
            kw = line.split(",")[0].strip().upper() + ("" if "LINEAR" not in line.upper() else " LINEAR")
            continue
        fields = [f.strip() for f in line.split(",") if f.strip()]
        if fields and all(re.fullmatch(_NUM, f) for f in fields):
            out.append((kw, [float(f) for f in fields]))
    return out


def _inp_factor(kw, k, fields):
    """The unit factor of data field ``k`` of a card (None: any unit conversion, checked to be one of them)."""
    if kw == "*NODE":
        return 1.0 if k == 0 else MM["length"]
    if kw == "*ELASTIC":
        return MM["stress"] if k == 0 else 1.0
    if kw == "*SPRING":
        return 1.0 if len(fields) == 1 and fields[0] in (1, 2, 3) else MM["stiffness"]
    if kw == "*CLOAD":
        return 1.0 if k < 2 else (MM["force"] if fields[1] <= 3 else MM["moment"])
    if kw == "*SURFACE BEHAVIOR LINEAR":
        return MM["slope"] if k == 0 else MM["stress"]
    return None


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    """The hex20r decks (CalculiX mortar and face-to-face, Abaqus, Nastran surface) of one small model, SI and mm."""
    from deckbridge.render import render_all
    out = {}
    for units in ("SI", "mm"):
        m = _model("hex20r", 0.03, 16, 2, 1, f"units={units}", "loads.T=2.0e5", "name=Q")
        folder = tmp_path_factory.mktemp(f"decks_{units}")
        out[units] = {p.name: p for p in render_all(m, folder, names=["calculix", "abaqus", "nastran_surface"])}
    return out


def test_units_mm_decks_carry_the_converted_numbers(decks):
    """Every data line of every inp deck: same cards, each number the SI deck's x its unit factor (written to 13
    digits: 1e-11). Coordinates x 1e3, E x 1e-6, springs x 1e-3, the moment x 1e3 and forces x 1 (*CLOAD),
    the face-to-face slope x 1e-9 and its tension x 1e-6; any other number that differs must differ by one of
    the unit factors (Abaqus contact controls: a length)."""
    si, mm = decks["SI"], decks["mm"]
    inps = sorted(n for n in si if n.endswith(".inp"))
    assert {"Q_ccx_lagrange.inp", "Q_ccx_f2f.inp", "Q_lagrange.inp"} <= set(inps) and sorted(mm) == sorted(si)
    seen = set()
    for name in inps:
        a, b = _inp_cards(si[name]), _inp_cards(mm[name])
        assert [k for k, _ in a] == [k for k, _ in b] and [len(f) for _, f in a] == [len(f) for _, f in b], name
        for (kw, fa), (_, fb) in zip(a, b):
            for k, (x, y) in enumerate(zip(fa, fb)):
                f = _inp_factor(kw, k, fa)
                if f is None:
                    assert y == pytest.approx(x, rel=1e-11) or any(
                        y == pytest.approx(x * g, rel=1e-11) for g in MM.values()), (name, kw, x, y)
                    continue
                assert y == pytest.approx(x * f, rel=1e-11, abs=1e-300), (name, kw, k, x, y)
                if x != 0 and f != 1.0:
                    seen.add((name, kw))
        assert "deckbridge-units: mm" in mm[name].read_text()
    for kw in ("*NODE", "*ELASTIC", "*SPRING", "*CLOAD"):
        assert all((n, kw) in seen for n in inps), kw
    assert ("Q_ccx_f2f.inp", "*SURFACE BEHAVIOR LINEAR") in seen


def test_units_mm_nastran_surface_deck_carries_the_converted_numbers(decks):
    """The Nastran surface deck read by pyNastran: GRID x 1e3, MAT1 E x 1e-6, CELAS2 x 1e-3, FORCE x 1, MOMENT x 1e3."""
    from pyNastran.bdf.bdf import BDF
    name = next(n for n in decks["SI"] if n.endswith(".bdf"))
    a, b = BDF(debug=None), BDF(debug=None)
    a.read_bdf(str(decks["SI"][name]), xref=False)
    b.read_bdf(str(decks["mm"][name]), xref=False)
    assert sorted(a.nodes) == sorted(b.nodes) and len(a.nodes) > 0
    xa = np.array([a.nodes[i].xyz for i in sorted(a.nodes)])
    xb = np.array([b.nodes[i].xyz for i in sorted(b.nodes)])
    np.testing.assert_allclose(xb, xa * MM["length"], rtol=1e-12, atol=1e-9)
    for mid in a.materials:
        assert b.materials[mid].e == pytest.approx(a.materials[mid].e * MM["stress"], rel=1e-12)
    springs = [e for e in a.elements.values() if e.type == "CELAS2"]
    assert springs
    for e in springs:
        assert b.elements[e.eid].k == pytest.approx(e.k * MM["stiffness"], rel=1e-12)
    n = 0
    for sid, loads in a.loads.items():
        for la, lb in zip(loads, b.loads[sid]):
            if la.type in ("FORCE", "MOMENT"):
                f = MM["force"] if la.type == "FORCE" else MM["moment"]
                assert lb.mag * np.asarray(lb.xyz) == pytest.approx(la.mag * np.asarray(la.xyz) * f, rel=1e-12)
                n += la.mag != 0
    assert n >= 2


@pytest.fixture(scope="module")
def ccx_tables(tmp_path_factory):
    """{(deck, units): (model, contact table read back)} of ccx 2.20 runs of the tet10 decks (16 x 2 x 1, t/R 0.03,
    distributing top, no stop, lambda 0.5 and 1: past liftoff), each run once."""
    import shutil

    from ccx_job import ccx_job
    from deckbridge.readers import read
    if shutil.which("ccx") is None:
        pytest.skip("CalculiX ccx not installed")
    cache = {}

    def get(deck, units):
        if (deck, units) not in cache:
            m = _model("tet10", 0.03, 16, 2, 1, f"units={units}", "steps.increments=2",
                       "load_introduction=distributing", "name=Q")
            job = ccx_job(m, tmp_path_factory.mktemp(f"ccx_{deck}_{units}"), deck)
            cache[deck, units] = m, read(job.with_suffix(".dat" if deck == "lagrange" else ".frd"), model=m), job
        return cache[deck, units]
    return get


@pytest.mark.parametrize("deck", ["f2f", "lagrange"])
def test_units_mm_ccx_results_read_back_as_si(ccx_tables, deck):
    """ccx runs the face-to-face and mortar decks in SI and in mm: the contact tables read back (mm converted to SI
    by the readers, the mortar rows through the face matrix) agree to 1e-5 of each column's largest value (gaps:
    of the largest gap; closed gaps are round-off, ~1e-31 m): ccx prints 6-7 significant digits (.frd E12.5,
    .dat E13.6), so two runs in other units agree to the last printed digit, not to 1e-9."""
    (_, a, _), (_, b, _) = ccx_tables(deck, "SI"), ccx_tables(deck, "mm")
    j = a.merge(b, on=["step", "increment", "node", "surface"], suffixes=("_si", "_mm"))
    assert len(j) == len(a) == len(b) and len(j) > 0
    for col in ("sigma_n_pa", "gap_m", "force_n", "area_m2", "r", "theta_deg", "load_factor"):
        si, mm = j[f"{col}_si"].to_numpy(float), j[f"{col}_mm"].to_numpy(float)
        assert (np.isnan(si) == np.isnan(mm)).all(), f"{deck} {col}: known in one unit system only"
        d = np.nanmax(np.abs(si - mm), initial=0.0) / max(np.nanmax(np.abs(si), initial=0.0), 1e-300)
        assert d <= 1e-5, f"{deck} {col}: SI vs mm differ by {d:.3g} of the largest"
    assert j.gap_m_si.max() > 1e-3 * j.gap_m_si.abs().max() > 0        # lifted: the gaps compared are not round-off


@pytest.mark.parametrize("deck", ["lagrange", "f2f"])
def test_ccx_forces_add_up_to_n_and_carry_the_moment(ccx_tables, deck):
    """The exact contact resultant of ccx in mm (tet10 16 x 2 x 1, past liftoff at lambda 1) balances N and the
    applied moment at every state (ccx's equilibrium: 1e-3 of N and of N R, the scenario matrix's). Mortar: the
    table's force_n (RF . n of the slave nodes; measured N 1.2e-8, moments <= 1.7e-8). Face-to-face: ccx prints no
    slave nodal force, the table's force_n is unknown (NaN: CPRESS x area is no nodal force, its sum missed N by
    -0.69 % here, +0.49 % / +0.67 % on tet10 / hex20r 32 x 4 x 1 at lambda 1, My 4.4e-3 of N R); the resultant is
    the clamped master ring's RF (result_files.f2f_master_resultant; measured N 2e-8, My 1.1e-5 at lambda 1). The
    mortar table's pressure x area about the nodes misses My by 1.9e-3 / 3.7e-3 at lambda 0.5 / 1."""
    from ccx_f2f_resultant import f2f_resultants
    m, t, job = ccx_tables(deck, "mm")
    tab = t[t.surface == "table"]
    assert tab.load_factor.max() == pytest.approx(1.0)
    n, nr = m.loads.N, m.loads.N * m.geometry.radius
    lv = m.load_vectors()
    if deck == "f2f":
        assert tab.force_n.isna().all()
        states = f2f_resultants(job, m.steps.lambda_max)
    else:
        th = np.radians(tab.theta_deg.to_numpy(float))
        xyz = np.c_[tab.r * np.cos(th), tab.r * np.sin(th), tab.z]
        f = np.c_[np.zeros((len(tab), 2)), tab.force_n.to_numpy(float)]
        states = {}
        for lam in tab.load_factor.unique():
            k = (tab.load_factor == lam).to_numpy()
            states[lam] = (f[k].sum(axis=0), np.cross(xyz[k], f[k]).sum(axis=0))
    assert len(states) == tab.groupby(["step", "increment"]).ngroups
    for lam, (F, M) in states.items():
        ref = np.array([0.0, 0.0, m.geometry.height])
        f_app = np.asarray(lv["N_force"], float) + lam * np.asarray(lv["T_force"], float)
        m_app = lam * np.asarray(lv["M_moment"], float) + np.cross(ref, f_app)
        assert abs(F[2] + f_app[2]) <= 1e-3 * n, (lam, F)
        assert np.abs(M[:2] + m_app[:2]).max() <= 1e-3 * nr, (lam, M)


# ---- friction ----------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("element", ["hex20r", "tet10", "hex20", "wedge15"])
def test_friction_on_quadratic_faces_refused_in_one_line_naming_the_key(tmp_path, element):
    """Friction on 8-/6-node faces solves without the radial stop (tests/test_friction_quadratic_skirt.py); with
    the stop the reference solve and ``run`` refuse it before any work, in one line naming contact.stop.side and
    the element (a base corner's tangential axis is the stop's normal: reference_solver/friction_face.py)."""
    from deckbridge.errors import ModelError
    from deckbridge.job import run_job
    from deckbridge.solve import solve_model
    m = _model(element, 0.005, 16, 2, 1, "contact.tangential=friction", "contact.friction=0.3",
               "contact.stop.side=inner")
    for job in (lambda: solve_model(m, "lagrange"), lambda: solve_model(m, "penalty"),
                lambda: run_job(m, tmp_path / "run", with_ccx=False, echo=lambda s: None)):
        with pytest.raises(ModelError) as err:
            job()
        msg = str(err.value)
        assert "\n" not in msg and msg.startswith("contact.stop.side = 'inner'") and f"mesh.element={element}" in msg
    # refused before anything is written (job.run_job: solve.check_solvable before the output folder)
    assert not list(tmp_path.rglob("*"))


# ---- reading the reference's own output back ----------------------------------------------------------------------

def test_reference_face_penalty_folder_reads_back_and_a_flipped_sign_is_refused(tmp_path):
    """``run`` on a tet10 skirt (16 x 4 x 2, t/R 0.03, distributing top, no stop, past liftoff at lambda 1): both
    reference folders read back through the contact-law check; the face-integrated penalty's sigma_N is the
    projection -D^-T r, which rings at the contact edge (here -18 kPa at a row open by 4.6e-6 m at lambda 0.6;
    up to 4.5 % of the peak at open rows on the quadratic matrix cases) and was refused as a flipped sign. A
    table whose signs are flipped is still refused."""
    from deckbridge.errors import InputError
    from deckbridge.job import run_job
    from deckbridge.readers import read
    m = _model("tet10", 0.03, 16, 4, 2, "load_introduction=distributing", "loads.T=2.0e5")
    run_job(m, tmp_path / "run", with_ccx=False, echo=lambda s: None)
    for method in METHODS:
        t = read(tmp_path / "run" / f"reference_{method}", model=m)
        assert (t[t.load_factor == t.load_factor.max()].status == "open").any()           # past liftoff
    csv = tmp_path / "run" / "reference_penalty" / "contact.csv"
    import pandas as pd
    df = pd.read_csv(csv)
    df["sigma_n_pa"], df["force_n"] = -df["sigma_n_pa"], -df["force_n"]
    df.to_csv(csv, index=False)
    with pytest.raises(InputError, match="contradicts the contact law"):
        read(tmp_path / "run" / "reference_penalty", model=m)
