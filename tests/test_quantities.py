"""The comparator's quantities against independent truths: force balance, the closed form N / (2 pi R t),
`deckbridge liftoff`, state changes just below / above an exact onset, CalculiX 2.20 runs."""

import shutil

import numpy as np
import pandas as pd
import pytest

import reference_solver as rs
from deckbridge import quantities as Q
from deckbridge.compare import compare_tables
from deckbridge.dialects.calculix.runner import run
from deckbridge.mesh import build_mesh
from deckbridge.model import load
from deckbridge.readers import read
from deckbridge.render import render_all
from deckbridge.results import SourceResult
from deckbridge.solve import condense_model, reactions, solve_system
from deckbridge.studies.liftoff import critical_load
from deckbridge.dialects.calculix.el_stress import ccx_wall
from deckbridge.wall_stress import azimuth_groups, reference_section_onset, reference_wall
from reference_solver.onset import group_open

needs_ccx = pytest.mark.skipif(shutil.which("ccx") is None, reason="CalculiX ccx not installed")
SMALL = ["mesh.n_theta=32", "mesh.n_z=6", "mesh.n_r=2"]


@pytest.fixture(scope="module")
def ref():
    """Both methods on the small mesh, lambda 0 .. 1 in 4 increments (0.5 is a state)."""
    model = load(None, SMALL + ["steps.increments=4"])
    mesh, system = condense_model(model)
    out = {}
    for method in ("penalty", "lagrange"):
        df, summary, sol = solve_system(model, mesh, system, method, recover=False)
        summary["section_liftoff_load_factor"], summary["section_liftoff_theta_deg"] = \
            reference_section_onset(system, mesh, sol)
        out[method] = SourceResult(df, f"ref_{method}", summary=summary, wall=reference_wall(system, mesh, sol))
    return model, mesh, system, out


def _state(df, lam):
    return df[(df.step == 2) & np.isclose(df.load_factor, lam)]


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_sum_sigma_times_area_is_the_vertical_reaction(ref, method):
    model, _, _, out = ref
    df = out[method].table
    s1 = df[(df.step == 1) & (df.surface == "table")]
    assert -Q.contact_resultant(s1) == pytest.approx(model.loads.N, rel=1e-9)
    np.testing.assert_allclose(s1.sigma_n_pa * s1.area_m2, -s1.force_n, rtol=1e-12)
    # the through-wall sigma_N is the resultant over the area, not the node mean (areas 1 : 2 : 1)
    last = _state(df, 1.0)
    sw = Q.sigma_n_wall(last)
    tb = last[last.surface == "table"]
    th = tb.theta_deg.round(6)
    want = -(tb.force_n.groupby(th).sum() / tb.area_m2.groupby(th).sum())
    np.testing.assert_allclose(sw.to_numpy(), want.sort_index().to_numpy(), rtol=1e-12)


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_base_sigma_zz_balances_sigma_n_and_matches_the_closed_form(ref, method):
    model, _, _, out = ref
    res = compare_tables([out[method]], load_factors=[0.0, 0.5])
    s0 = -model.loads.N / (2 * np.pi * model.geometry.radius * model.geometry.thickness)
    ex0 = res.points[0].extra[f"reference/{method}"]
    for k in ("szz_inner_pa", "szz_outer_pa"):
        np.testing.assert_allclose(ex0["szz_pa"][k], s0, rtol=0.01, err_msg=k)
    ex = res.points[1].extra[f"reference/{method}"]
    assert ex["szz_local_residual"] < 0.01 and ex["szz_resultant_residual"] < 0.01 and not ex["warn"]


def test_first_node_onset_of_a_reference_source_is_deckbridge_liftoffs(ref):
    model, _, _, out = ref
    want = critical_load(model, tol=1e-7)
    res = compare_tables([out["penalty"], out["lagrange"]])
    for m in ("penalty", "lagrange"):
        o = res.onsets[f"reference/{m}"]["first_node"]
        assert o["exact"] == pytest.approx(want[m]["lambda_c"], abs=1e-6)
        assert o["bracket"][0] <= o["exact"] <= o["bracket"][1]
        s = res.summary()["sources"][f"reference/{m}"]["onset_first_node"]
        assert s["exact"] == o["exact"] and s["interpolated"] != s["exact"]     # separate keys


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_section_onset_is_where_a_whole_azimuth_opens(ref, method):
    """Just below the exact value no azimuth is open through the wall, just above one is."""
    model, mesh, system, out = ref
    lam = out[method].summary["section_liftoff_load_factor"]
    groups, _ = azimuth_groups(system, mesh)
    kf = out[method].summary["penalty_k"]["k_factor"] if method == "penalty" else 1.0
    for d, want in ((-1e-7, False), (1e-7, True)):
        s = rs.solve_path(system, method, kf, lambda_max=lam + d, increments=1, liftoff_surface="none", recover=False)
        assert group_open(s.gap[-1], s.closed[-1], groups).any() == want
    first = out[method].summary["liftoff_load_factor"]
    assert first < lam


def test_identical_sources_and_a_zone_through_zero(ref):
    _, _, _, out = ref
    a = out["lagrange"]
    b = SourceResult(a.table.copy(), "copy", summary=a.summary)
    res = compare_tables([a, b], origins=["x/a", "y/b"])
    for pt in res.points:
        p = pt.pairs[0]
        assert p["max_abs_diff_pa"] == 0.0
        assert p["liftoff_zone_overlap_tol"] in (1.0, None) and p["liftoff_zone_overlap"] == 1.0
    zones = res.primary.zones[res.labels[0]]
    wraps = [z for z in zones if z[0] > z[1]]                           # [start, end] through 0
    assert len(wraps) == 1 and wraps[0][0] > 180.0 > wraps[0][1]        # one zone, not two halves
    assert not any(z[0] == 0.0 or z[1] == 0.0 for z in zones)
    assert res.points[0].peaks[res.labels[0]][1] is None                   # lambda = 0: uniform, no location


# --- CalculiX --------------------------------------------------------------------------------------
def _with_base_stress_print(text: str, n_elems: int) -> str:
    """*EL PRINT S of the bottom element row (ids 1..n_r*n_theta), when the deck does not request it."""
    if "*EL PRINT" in text.upper():
        return text
    ids = np.arange(1, n_elems + 1)
    elset = "*ELSET, ELSET=EBASE\n" + "\n".join(", ".join(map(str, ids[a:a + 16])) for a in range(0, n_elems, 16))
    text = text.replace("*MATERIAL,", elset + "\n*MATERIAL,", 1)
    return text.replace("*END STEP", "*EL PRINT, ELSET=EBASE\nS\n*END STEP")


@pytest.fixture(scope="module")
def ccx(tmp_path_factory):
    """The CalculiX mortar deck (NLGEOM removed, as the reference) on a small mesh without stop, lambda
    0 .. 1 in 10 increments, with the base-row stresses printed."""
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=2", "contact.stop.side=none"])
    mesh = build_mesh(model)
    folder = tmp_path_factory.mktemp("ccx_q")
    path = next(p for p in render_all(model, folder, names=["calculix"]) if "lagrange" in p.name)
    text = _with_base_stress_print(path.read_text(), mesh.n_r * mesh.n_theta)
    path.write_text(text.replace("*STEP, NLGEOM, INC=", "*STEP, INC="))
    dat = run(path, timeout_s=180).dat
    src = SourceResult(read(path.with_suffix(".frd"), model=model), str(path),
                       wall=ccx_wall(dat, model, mesh))
    return model, mesh, src


@needs_ccx
def test_ccx_forces_balance_and_sigma_zz_balances_sigma_n(ccx):
    model, _, src = ccx
    df = src.table
    s1 = df[(df.step == 1) & (df.surface == "table")]
    s1 = s1[s1.increment == s1.increment.max()]
    # exactly the printed nodal forces (force_n = RF . n), and N to ccx's print precision
    np.testing.assert_allclose(-(s1.sigma_n_pa * s1.area_m2).sum(), s1.force_n.sum(), rtol=1e-9)
    assert s1.force_n.sum() == pytest.approx(model.loads.N, rel=1e-5)
    res = compare_tables([src], load_factors=[0.5])
    ex = res.primary.extra[res.labels[0]]
    assert ex["szz_local_residual"] < 0.01 and ex["szz_resultant_residual"] < 0.01


@needs_ccx
def test_ccx_onset_bracket_holds_the_exact_reference_value(ccx):
    model, mesh, src = ccx
    _, system = condense_model(model, mesh)
    _, summary, sol = solve_system(model, mesh, system, "lagrange", recover=False)
    res = compare_tables([src])
    o = res.onsets[res.labels[0]]["first_node"]
    assert o["exact"] is None and o["bracket"] is not None
    lo, hi = o["bracket"]
    step = model.steps.lambda_max / model.steps.increments
    assert lo - step <= summary["liftoff_load_factor"] <= hi + step       # in or next to it
    sec = res.onsets[res.labels[0]]["section"]
    assert sec["bracket"] is not None and sec["bracket"][1] >= lo


def test_line_load_is_the_through_wall_stress_times_the_thickness_on_a_uniform_state(ref):
    """Under N alone q = -N / (2 pi R_mid) up to the faceting: Sum q x arc = the resultant exactly."""
    model, _, _, out = ref
    res = compare_tables([out["penalty"]], load_factors=[0.0])
    q = res.primary.extra["reference/penalty"]["line_load_n_per_m"]
    arc = np.radians(360.0 / model.mesh.n_theta) * model.geometry.radius
    assert np.sum(q["q"]) * arc == pytest.approx(-model.loads.N, rel=1e-9)
    np.testing.assert_allclose(q["q"], -model.loads.N / (2 * np.pi * model.geometry.radius), rtol=1e-9)


def test_zone_rules_min_width_tolerance_and_uniform_peak():
    from deckbridge.compare.metrics import liftoff_zones, peak_compression, zone_iou_tol
    from deckbridge.compare.profile import Profile
    th = np.arange(36) * 10.0
    s = -np.ones(36)
    s[0] = 0.0                                            # one open node at 0 deg: narrower than an element arc
    p = Profile(th, s, s == 0.0)
    assert liftoff_zones(p) == [] and liftoff_zones(p, min_width_deg=0.0) == [[0.0, 0.0]]
    s2 = -np.cos(np.radians(th)) - 0.5                    # lifted where cos < -0.5: (120, 240)
    assert len(liftoff_zones(Profile(th, s2, np.zeros(36, bool)))) == 1
    # zones one element arc apart overlap fully with the tolerance, partly without
    assert zone_iou_tol([[350.0, 30.0]], [[355.0, 35.0]], 10.0) == 1.0
    assert zone_iou_tol([], [], 10.0) is None
    assert zone_iou_tol([[0.0, 20.0]], [[180.0, 200.0]], 10.0) == 0.0
    # lambda = 0: round-off spread -> no location
    assert peak_compression(Profile(th, -14.3e6 * (1 + 1e-13 * np.sin(th)), np.zeros(36, bool)))[1] is None


def test_open_gap_tension_is_kept_and_warned():
    df = pd.DataFrame({"surface": "table", "theta_deg": [0.0, 0.0, 180.0, 180.0], "r": [1.49, 1.51] * 2,
                       "sigma_n_pa": [2e6, 1e6, -100e6, -90e6], "status": ["open", "open", "closed", "closed"],
                       "area_m2": [1.0, 1.0, 1.0, 1.0], "force_n": [-2e6, -1e6, 100e6, 90e6], "wall": [0, 1] * 2})
    t = Q.open_tension(df)
    assert t["max_open_sigma_n_pa"] == 2e6 and t["open_tension_ratio"] == pytest.approx(0.02) and t["warn"]
    assert Q.sigma_n_wall(df).loc[0.0] == pytest.approx(1.5e6)        # tension stays sigma_N > 0


def test_cone_base_check_is_the_force_balance_and_its_residual_falls_with_the_element_height():
    """Issue 21.10 (cone, top_radius 1.6: warnings of 1.6-1.7 % at lambda = 0 on 24 x 2 x 1). The quantity
    is right: sigma_zz is the vertical traction on the horizontal base section, so Sum sigma_zz x area is
    the vertical reaction whatever the wall's slope, and the solver's reactions balance N to 1e-9. What
    the residual measures is the reference C3D8I's recovered sigma_zz, whose error is O(element height):
    it halves when n_z doubles (a wrong quantity would not fall), and the cylinder reads 0."""
    res = {}
    for nz in (2, 4):
        m = load(None, ["mesh.n_theta=24", f"mesh.n_z={nz}", "mesh.n_r=1", "geometry.top_radius=1.6"])
        mesh, system = condense_model(m)
        df, _, sol = solve_system(m, mesh, system, "penalty", recover=True)
        F, _ = reactions(system.problem, sol, 0)
        assert F[2] == pytest.approx(m.loads.N, rel=1e-9)                     # the solver balances
        wall = reference_wall(system, mesh, sol)
        s1 = df[df.step == 1]
        res[nz] = Q.equilibrium(wall[wall.step == 1], s1[s1.increment == s1.increment.max()])["szz_resultant_residual"]
    assert 0.012 < res[2] < 0.02 and res[4] / res[2] == pytest.approx(0.5, abs=0.05)
    m = load(None, ["mesh.n_theta=24", "mesh.n_z=2", "mesh.n_r=1"])
    mesh, system = condense_model(m)
    df, _, sol = solve_system(m, mesh, system, "penalty", recover=True)
    wall = reference_wall(system, mesh, sol)
    s1 = df[df.step == 1]
    assert Q.equilibrium(wall[wall.step == 1], s1[s1.increment == s1.increment.max()])["szz_resultant_residual"] < 1e-6


def test_force_n_of_an_8_node_face_is_the_nodal_force_and_the_pressure_weighs_the_sums():
    """One 8-node face (area 1 m^2) pressed by p: sigma_N = -p at every node on the hat areas (corners 1/24, mid-sides
    5/24), force_n the consistent nodal forces (corners -p/12: they pull, mid-sides p/3; quantities.DEFINITIONS).
    The table conforms (Sum force_n = -Sum sigma_N area), the through-wall sigma_N is -p, no corner reads as a
    penetration without force, and a table whose forces have the wrong sign is refused."""
    from deckbridge.results import ResultsError, conform
    p = 2e6
    corner = np.array([1, 0, 1, 0, 1, 0, 1, 0], bool)         # around the face: corner, mid-side, corner, ...
    theta = [0.0, 1.0, 2.0, 2.0, 2.0, 1.0, 0.0, 0.0]
    r = [1.49, 1.49, 1.49, 1.50, 1.51, 1.51, 1.51, 1.50]
    df = pd.DataFrame({"source": "reference", "method": "lagrange", "step": 1, "increment": 1, "load_factor": 0.0,
                       "node": np.arange(1, 9), "surface": "table", "theta_deg": theta, "z": 0.0, "r": r,
                       "sigma_n_pa": -p, "gap_m": -1e-6, "status": "closed",
                       "area_m2": np.where(corner, 1 / 24, 5 / 24), "force_n": np.where(corner, -p / 12, p / 3)})
    t = conform(df)
    assert t.force_n.sum() == pytest.approx(p, rel=1e-12) and (t.force_n[corner] < 0).all()
    np.testing.assert_allclose(Q.sigma_n_wall(t).to_numpy(), -p, rtol=1e-12)
    assert Q.free_penetration(t)["free_penetration_m"] == 0.0
    with pytest.raises(ResultsError, match="Sum force_n"):
        conform(df.assign(force_n=-df.force_n))
