"""Comparator on synthetic tables with known answers, and the ``compare`` command's bad-input behaviour.

Known answers: shifted / scaled cosine curves (max difference, where, rms, exact on uniform grids
by discrete orthogonality), liftoff intervals whose ends sit on grid points (wrapping through 0),
the linear-interpolation error bound h^2/8 max|f''| between meshes of different n_theta, and the
beam-theory liftoff load factor lambda = N R / (2 M_b) of the reference (kern of a thin ring).
"""

import json
import math

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.compare import LoadFactorError, compare_tables
from deckbridge.compare.metrics import zone_iou
from deckbridge.errors import DeckbridgeError
from deckbridge.model import load
from deckbridge.results import COLUMNS, REQUIRED, conform

MPA = 1e6


def make_table(source, method, n_theta, sigma, lams=(1.0,), n_wall=1, wall_split=0.0, open_zero=False):
    """Tidy table: step 1 (one increment, lambda 0) + step 2 increments at ``lams``.

    ``sigma(theta_deg, lam)`` [Pa]; ``n_wall`` nodes per azimuth at sigma -/+ wall_split (mean = sigma).
    ``open_zero``: lifted nodes carry sigma 0 and status open (Lagrange-like).
    """
    th = 360.0 * np.arange(n_theta) / n_theta
    rows = []
    states = [(1, 1, 0.0)] + [(2, k, float(l)) for k, l in enumerate(lams, 1)]
    for step, inc, lam in states:
        s = sigma(th, lam)
        for w in range(n_wall):
            off = 0.0 if n_wall == 1 else wall_split * (2 * w / (n_wall - 1) - 1)
            v = s + off
            up = v > 0
            if open_zero:
                v = np.where(up, 0.0, v)
            for j in range(n_theta):
                rows.append((source, method, step, inc, lam, w * n_theta + j + 1, "table", th[j], 0.0,
                             1.5 + 0.01 * w, v[j], 1e-5 if up[j] else 0.0, "open" if up[j] else "closed"))
    return conform(pd.DataFrame(rows, columns=REQUIRED))


def beam(model):
    """Beam-theory sigma_N(theta, lam) of a thin ring in full contact (REFERENCE.md section 3)."""
    g = model.geometry
    n_term = -model.loads.N / (2 * math.pi * g.radius * g.thickness)
    m_term = model.base_moment / (math.pi * g.radius ** 2 * g.thickness)
    return lambda th, lam: n_term + lam * m_term * np.cos(np.radians(th - model.loads.azimuth))


def test_curves_shifted_in_azimuth_give_the_known_difference():
    """b(theta) = a(theta - 30): d = 2 A sin(15) sin(theta - 15): max at 105 deg, rms = sqrt(2) A sin(15)."""
    amp = 20 * MPA
    a = make_table("reference", "penalty", 24, lambda t, l: -10 * MPA + amp * np.cos(np.radians(t)))
    b = make_table("reference", "lagrange", 24, lambda t, l: -10 * MPA + amp * np.cos(np.radians(t - 30)))
    pair = compare_tables([a, b], load_factors=[1.0]).primary.pairs[0]
    assert pair["a"] == "reference/penalty" and pair["b"] == "reference/lagrange"
    assert pair["max_abs_diff_pa"] == pytest.approx(2 * amp * math.sin(math.radians(15)), rel=1e-12)
    assert pair["theta_of_max_diff_deg"] == pytest.approx(105.0)
    assert pair["rms_diff_pa"] == pytest.approx(math.sqrt(2) * amp * math.sin(math.radians(15)), rel=1e-12)


def test_scaled_and_offset_curve_gives_the_known_difference():
    """b = 1.25 a - 1 MPa with a = -10 + 16 cos(theta) MPa: d = -3.5 + 4 cos(theta) MPa.

    max |d| = 7.5 MPa at 180 deg; rms = sqrt(3.5^2 + 4^2 / 2) = 4.5 MPa. Two wall nodes per azimuth
    (+-3 MPa) average to the curve.
    """
    f = lambda t, l: -10 * MPA + 16 * MPA * np.cos(np.radians(t))  # noqa: E731
    a = make_table("ccx", "mortar", 36, f, n_wall=2, wall_split=3 * MPA)
    b = make_table("reference", "penalty", 36, lambda t, l: 1.25 * f(t, l) - 1 * MPA)
    res = compare_tables([a, b], load_factors=[1.0])
    pair = res.primary.pairs[0]
    assert pair["max_abs_diff_pa"] == pytest.approx(7.5 * MPA, rel=1e-12)
    assert pair["theta_of_max_diff_deg"] == pytest.approx(180.0)
    assert pair["rms_diff_pa"] == pytest.approx(4.5 * MPA, rel=1e-12)
    assert res.primary.peaks["ccx/mortar"] == pytest.approx((-26 * MPA, 180.0))


def test_liftoff_zones_including_one_wrapping_through_zero():
    """a lifts where cos(theta) > cos 40: [320, 40]; b where cos(theta - 10) > cos 20: [350, 30];
    c (two zones, as the paper's penalty curves) where cos(2 theta) > cos 30: [345, 15] and [165, 195].
    Zone ends lie on grid points, so the zones are exact. IoU(a, b) = 40/80; IoU(a, c) = 30/110;
    IoU(b, c) = 25 / (40 + 60 - 25)."""
    amp = 10 * MPA
    a = make_table("s", "a", 36, lambda t, l: amp * (np.cos(np.radians(t)) - math.cos(math.radians(40))))
    b = make_table("s", "b", 36, lambda t, l: amp * (np.cos(np.radians(t - 10)) - math.cos(math.radians(20))))
    c = make_table("s", "c", 72, lambda t, l: amp * (np.cos(np.radians(2 * t)) - math.cos(math.radians(30))))
    pt = compare_tables([a, b, c], load_factors=[1.0]).primary
    assert pt.zones["s/a"] == [pytest.approx([320.0, 40.0], abs=1e-6)]
    assert pt.zones["s/b"] == [pytest.approx([350.0, 30.0], abs=1e-6)]
    assert sorted(pt.zones["s/c"]) == [pytest.approx([165.0, 195.0], abs=1e-6), pytest.approx([345.0, 15.0], abs=1e-6)]
    iou = {(p["a"], p["b"]): p["liftoff_zone_overlap"] for p in pt.pairs}
    assert iou[("s/a", "s/b")] == pytest.approx(0.5, abs=1e-8)
    assert iou[("s/a", "s/c")] == pytest.approx(30 / 110, abs=1e-8)
    assert iou[("s/b", "s/c")] == pytest.approx(25 / 75, abs=1e-8)


def test_zone_overlap_definition_on_the_circle():
    assert zone_iou([], []) == 1.0
    assert zone_iou([[350.0, 10.0]], []) == 0.0
    assert zone_iou([[0.0, 360.0]], [[90.0, 270.0]]) == pytest.approx(0.5)
    assert zone_iou([[350.0, 10.0]], [[0.0, 20.0]]) == pytest.approx(10 / 30)
    assert zone_iou([[350.0, 10.0]], [[350.0, 10.0]]) == pytest.approx(1.0)


def test_meshes_of_different_n_theta_are_interpolated_within_the_linear_bound():
    """f = A cos(theta) + B cos(2 theta) sampled on 24 and 36 azimuths: on the union grid the
    24-mesh is interpolated; its error stays below h^2/8 max|f''| (h = 15 deg) but is not zero."""
    amp_a, amp_b = 20 * MPA, 5 * MPA
    f = lambda t, l: amp_a * np.cos(np.radians(t)) + amp_b * np.cos(np.radians(2 * t))  # noqa: E731
    coarse = make_table("ccx", "penalty", 24, f)
    fine = make_table("reference", "penalty", 36, f)
    pt = compare_tables([coarse, fine], load_factors=[1.0]).primary
    grid = pt.aligned.index.to_numpy()
    assert grid.size == 24 + 36 - 12                   # union: common azimuths every 30 deg
    err = np.abs(pt.aligned["ccx/penalty"].to_numpy() - f(grid, 1.0))
    bound = math.radians(15.0) ** 2 / 8 * (amp_a + 4 * amp_b)
    assert err.max() <= bound
    assert err.max() > 0.2 * bound
    assert pt.pairs[0]["max_abs_diff_pa"] == pytest.approx(err.max())
    on_fine = np.isin(np.round(grid, 6), np.round(360.0 * np.arange(36) / 36, 6))
    assert np.allclose(pt.aligned["reference/penalty"].to_numpy()[on_fine], f(grid[on_fine], 1.0), rtol=0, atol=1e-6)


def test_liftoff_load_factor_and_default_load_factors_follow_beam_theory():
    """Beam theory: liftoff at lambda = N R / (2 M_b). sigma_N is linear in lambda before liftoff, so
    extrapolating from the two increments before recovers it exactly, for a penalty-like source and
    for a Lagrange-like one (lifted nodes open with sigma_N = 0, whose zone ends on the open nodes).
    Defaults: end of step 1, the first increment after liftoff, lambda_max."""
    model = load(None, ["mesh.n_theta=24"])
    lams = np.round(np.arange(1, 11) / 10, 12)
    pen = make_table("reference", "penalty", 24, beam(model), lams=lams)
    lag = make_table("reference", "lagrange", 24, beam(model), lams=lams, open_zero=True)
    res = compare_tables([pen, lag])
    lam_c = model.loads.N * model.geometry.radius / (2 * model.base_moment)
    assert res.liftoff["reference/penalty"] == pytest.approx(lam_c, rel=1e-12)
    assert res.liftoff["reference/lagrange"] == pytest.approx(lam_c, rel=1e-12)
    assert [p.load_factor for p in res.points] == pytest.approx([0.0, 0.6, 1.0])
    assert res.points[0].zones == {"reference/penalty": [], "reference/lagrange": []}
    # at lambda = 1 beam theory lifts |theta| < arccos(lam_c): 53.45 deg; linear crossing within 0.5 deg
    half = math.degrees(math.acos(lam_c))
    zs, ze = res.primary.zones["reference/penalty"][0]
    assert zs == pytest.approx(360 - half, abs=0.5) and ze == pytest.approx(half, abs=0.5)
    assert res.primary.zones["reference/lagrange"] == [[315.0, 45.0]]
    # compression side: both identical (no lifted node there)
    assert res.primary.peaks["reference/penalty"] == pytest.approx(res.primary.peaks["reference/lagrange"])


def test_liftoff_onset_is_the_first_node_not_the_wall_mean():
    """Two wall nodes at -10 + 16 lam cos(theta) -+ 3 MPa: the outer node lifts at lam = 7/16, the
    wall mean (the plotted curve, whose zones are shaded) only at 10/16."""
    f = lambda t, l: -10 * MPA + 16 * MPA * l * np.cos(np.radians(t))  # noqa: E731
    res = compare_tables([make_table("r", "p", 24, f, lams=[0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7], n_wall=2,
                                     wall_split=3 * MPA)], load_factors=[0.5, 0.7])
    assert res.liftoff["r/p"] == pytest.approx(7 / 16, rel=1e-12)
    assert res.points[0].zones["r/p"] == []
    assert res.points[1].zones["r/p"] != []


def test_requested_load_factor_is_interpolated_or_refused():
    model = load(None, ["mesh.n_theta=24"])
    lams = np.round(np.arange(1, 11) / 10, 12)
    pen = make_table("reference", "penalty", 24, beam(model), lams=lams)
    short = make_table("ccx", "penalty", 24, beam(model), lams=lams[:5])
    pt = compare_tables([pen], load_factors=[0.55]).primary
    assert pt.peaks["reference/penalty"] == pytest.approx((float(beam(model)(180.0, 0.55)), 180.0), rel=1e-12)
    with pytest.raises(LoadFactorError, match=r"ccx/penalty.*load factor 0\.8 outside its range \[0, 0\.5\]"):
        compare_tables([pen, short], load_factors=[0.8])
    # defaults compare at the smallest lambda_max of the sources
    assert compare_tables([pen, short]).primary.load_factor == pytest.approx(0.5)


def test_equal_labels_get_their_folder_names_and_tables_without_table_rows_are_refused(tmp_path):
    f = lambda t, l: -MPA * np.ones_like(t)  # noqa: E731
    a, b = make_table("reference", "penalty", 16, f), make_table("reference", "penalty", 16, f)
    res = compare_tables([a, b], origins=[tmp_path / "run_a", tmp_path / "run_b" / "contact.csv"])
    assert res.labels == ["reference/penalty (run_a)", "reference/penalty (run_b)"]
    stop_only = a.assign(surface="stop")
    with pytest.raises(DeckbridgeError, match="no contact data on the table surface"):
        compare_tables([stop_only])


# --- the command line -------------------------------------------------------------------------

def _reference_folder(path, table, summary=None):
    path.mkdir(parents=True)
    table.to_csv(path / "contact.csv", index=False)
    (path / "summary.json").write_text(json.dumps(summary or {}))
    return path


def test_compare_command_writes_the_four_outputs(tmp_path, small_model):
    """Two reference folders on the 16-azimuth model: summary.json holds the comparator's numbers and
    discrepancy.csv the aligned curves with their difference."""
    (tmp_path / "m.yaml").write_text(small_model.to_yaml())
    f = beam(small_model)
    lams = np.round(np.arange(1, 11) / 10, 12)
    pen = _reference_folder(tmp_path / "pen", make_table("reference", "penalty", 16, f, lams=lams))
    lag = _reference_folder(tmp_path / "lag", make_table("reference", "lagrange", 16, lambda t, l: 0.9 * f(t, l), lams=lams))
    out = tmp_path / "out"
    r = CliRunner().invoke(main, ["compare", str(pen), str(lag), "-o", str(out), "--model", str(tmp_path / "m.yaml")])
    assert r.exit_code == 0, r.output
    assert sorted(p.name for p in out.iterdir()) == [".deckbridge-output", "discrepancy.csv", "report.html",
                                                     "sigma_n.png", "summary.json"]    # the marker names the command
    s = json.loads((out / "summary.json").read_text())
    assert s["load_factors"] == pytest.approx([0.0, 0.6, 1.0])
    lam_c = small_model.loads.N * small_model.geometry.radius / (2 * small_model.base_moment)
    onset = s["sources"]["reference/penalty"]["onset_first_node"]       # no solver summary: estimate + bracket
    assert onset["exact"] is None and onset["interpolated"] == pytest.approx(lam_c)
    assert onset["bracket"][0] <= lam_c <= onset["bracket"][1] and onset["bracket"] == pytest.approx([0.5, 0.6])
    pair = s["pairs"][0]
    # d = -0.1 f at lambda 1: largest at 180 deg (|f| largest)
    assert pair["max_abs_diff_pa"] == pytest.approx(0.1 * abs(f(180.0, 1.0)))
    assert pair["theta_of_max_diff_deg"] == pytest.approx(180.0)
    d = pd.read_csv(out / "discrepancy.csv")
    assert len(d) == 3 * 16
    last = d[d["load_factor"] == 1.0]
    diff = last["diff_pa reference/lagrange - reference/penalty"].to_numpy()
    assert np.allclose(diff, last["sigma_n_pa reference/lagrange"] - last["sigma_n_pa reference/penalty"])
    assert np.abs(diff).max() == pytest.approx(pair["max_abs_diff_pa"])
    assert (out / "sigma_n.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _fails(args, *needles):
    r = CliRunner().invoke(main, ["compare", *args])
    assert r.exit_code != 0
    line = r.output.strip()
    assert line.startswith("deckbridge: error:") and "\n" not in line, r.output
    for n in needles:
        assert n in line, line
    return line


def test_unreadable_or_mismatched_inputs_end_with_one_line_naming_the_file(tmp_path, small_model):
    (tmp_path / "m.yaml").write_text(small_model.to_yaml())
    model_opt = ["--model", str(tmp_path / "m.yaml")]
    out = str(tmp_path / "out")
    junk = tmp_path / "notes.txt"
    junk.write_text("this is not a result file\n")
    _fails([str(junk), "-o", out], "notes.txt", "format not recognised")
    # other model: node 999 is no slave node of the 16 x 4 x 1 model
    other = make_table("reference", "penalty", 16, lambda t, l: -MPA * np.ones_like(t))
    other.loc[0, "node"] = 999
    far = _reference_folder(tmp_path / "other", other)
    _fails([str(far), "-o", out, *model_opt], "other", "node 999", "another model")
    # same node ids, other azimuths (a 20-azimuth mesh read against the 16-azimuth model)
    moved = _reference_folder(tmp_path / "moved", make_table("reference", "penalty", 20, lambda t, l: -MPA * np.ones_like(t)))
    _fails([str(moved), "-o", out, *model_opt], "moved", "another model")
    # no contact data
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "contact.csv").write_text(",".join(COLUMNS) + "\n")
    (empty / "summary.json").write_text("{}")
    _fails([str(empty), "-o", out], "empty", "no contact data")
    # different units: radii in mm against a model in m; a unit the reader does not know
    mm = make_table("reference", "penalty", 16, lambda t, l: -MPA * np.ones_like(t))
    mm["r"] *= 1000.0
    _fails([str(_reference_folder(tmp_path / "in_mm", mm)), "-o", out, *model_opt], "in_mm", "different units")
    csv = tmp_path / "export.csv"
    csv.write_text("node,CPRESS [ksi]\n1,1.0\n")
    _fails([str(csv), "-o", out, *model_opt], "export.csv", "ksi")
    # a load factor outside a source's range
    ok = _reference_folder(tmp_path / "ok", make_table("reference", "penalty", 16, beam(small_model), lams=[0.5, 1.0]))
    _fails([str(ok), "-o", out, "--load-factor", "2"], "reference/penalty", "outside its range")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_headline_sits_inside_the_small_strain_range_past_liftoff(tmp_path):
    """Issue 21: the default comparison leads with the largest compared load factor whose lift / R <= 0.01
    in every source (here both reference methods on a 24 x 6 x 1 JAR), which is past liftoff (the lobes:
    a lifted zone), and still compares lambda_max. The lift is read from each Solution's gaps and the model's
    geometry (the node radii are R +- t/2), not from the comparison's tables."""
    from deckbridge.solve import condense_model, solve_system

    model = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"])
    mesh, system = condense_model(model)
    tables, lift = [], {}
    table = system.problem.contact_surface == "table"
    r_max = model.geometry.radius + model.geometry.thickness / 2
    for method in ("penalty", "lagrange"):
        df, _, sol = solve_system(model, mesh, system, method)
        tables.append(df)
        for k, lam in enumerate(sol.load_factor):
            lift[round(float(lam), 9)] = max(lift.get(round(float(lam), 9), 0.0),
                                             float(np.max(sol.gap[k, table], initial=0.0)) / r_max)
    res = compare_tables(tables)
    inside = [lam for lam, v in lift.items() if v <= 0.01]
    assert max(lift.values()) > 0.01                 # the load path goes past the small-strain range
    head = res.primary
    assert head.headline and head.load_factor == pytest.approx(max(inside))
    assert head.load_factor < model.steps.lambda_max
    assert res.points[-1].load_factor == pytest.approx(model.steps.lambda_max)     # still compared
    assert all(head.zones[lab] for lab in head.labels)          # past liftoff in both: the lifted zones
    assert "small-strain range" in head.what and "idealisations" in head.what
    assert res.summary()["primary_load_factor"] == pytest.approx(max(inside))
