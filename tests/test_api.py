"""The public Python API (``import deckbridge``, issue 25) against independent truths, off the default path:
a skirt R = 1.0 m, t = 0.03 m, H = 1.2 m, 24 x 4 x 1, loads N = 2 MN, T = 0.1 MN, M = 1.5 MN N m at azimuth 60 deg.

Truths: force balance (contact forces and base-wall sigma_zz carry N; friction and normal forces carry T
lambda in its direction), closed forms (uniform sigma_N = -N / A in step 1; penetration = force / k_normal;
beam-theory liftoff N R / (2 (M + T H))), the command line's own outputs (``deckbridge init``, ``solve``,
``compare``, ``liftoff``), and the tables the functions return computed again here from the tidy table.
"""

import json
import math

import meshio
import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

import deckbridge
from deckbridge import ModelError, summary_keys
from deckbridge.cli import main

OFF = {"geometry.radius": 1.0, "geometry.thickness": 0.03, "geometry.height": 1.2, "mesh.n_theta": 24,
       "mesh.n_z": 4, "mesh.n_r": 1, "loads.N": 2.0e6, "loads.T": 1.0e5, "loads.M": 1.5e6, "loads.azimuth": 60.0,
       "outputs.vtu": False}
SETS = [arg for k, v in OFF.items() for arg in ("--set", f"{k}={str(v).lower()}")]


def no_negative_zero(values) -> bool:
    a = np.asarray(values, float).ravel()
    return not bool(np.any((a == 0) & np.signbit(a)))


@pytest.fixture(scope="module")
def model():
    return deckbridge.default_model().with_overrides(OFF)


@pytest.fixture(scope="module")
def solved(model):
    return {m: deckbridge.solve(model, method=m) for m in ("penalty", "lagrange")}


def test_default_model_is_what_init_writes(tmp_path):
    r = CliRunner().invoke(main, ["init", str(tmp_path / "m.yaml")])
    assert r.exit_code == 0, r.output
    assert deckbridge.default_model() == deckbridge.load(tmp_path / "m.yaml") == deckbridge.load()


def test_with_overrides_takes_a_mapping_of_dotted_keys_as_the_cli_set(model, tmp_path):
    assert model == deckbridge.load(None, [s for s in SETS if s != "--set"])
    assert (model.geometry.radius, model.loads.azimuth, model.mesh.n_theta) == (1.0, 60.0, 24)
    with pytest.raises(ModelError, match="geometry.radiuss"):
        model.with_overrides({"geometry.radiuss": 2.0})


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_solve_balances_n_and_gives_a_uniform_step_1(solved, model, method):
    res = solved[method]
    s0 = res.sigma_n(0)                                    # end of step 1: N alone
    assert s0["force_n"].sum() == pytest.approx(2.0e6, rel=1e-9)
    wall = res.sigma_n_wall(0)["sigma_n_pa"]
    np.testing.assert_allclose(wall.to_numpy(), -2.0e6 / s0["area_m2"].sum(), rtol=1e-6)
    assert wall.mean() == pytest.approx(-2.0e6 / (2 * math.pi * 1.0 * 0.03), rel=0.015)   # the faceted ring's area
    ws = res.wall_stress(0)                                # base-wall sigma_zz carries N too
    assert (ws["szz_mean_pa"] * ws["area_m2"]).sum() == pytest.approx(-2.0e6, rel=1e-6)
    for table in (res.table, res.sigma_n_wall(1.0), res.sigma_n_path(), res.wall):
        assert no_negative_zero(table.select_dtypes(float).to_numpy() if isinstance(table, pd.DataFrame) else table)


def test_solve_onsets_near_beam_theory_and_where_the_load_opens(solved, model):
    bt = model.beam_theory_liftoff()
    assert bt == pytest.approx(2.0e6 * 1.0 / (2 * (1.5e6 + 1.0e5 * 1.2)), rel=1e-12)
    for res in solved.values():
        on = res.onsets
        assert on.loc["first_node", "load_factor"] == pytest.approx(bt, rel=0.1)
        assert on.loc["first_node", "load_factor"] <= on.loc["section", "load_factor"]
        assert on.loc["first_node", "theta_deg"] == pytest.approx(60.0)      # loads.azimuth opens first
        assert res.summary["beam_theory_liftoff_load_factor"] == pytest.approx(bt, rel=1e-12)


def test_solve_summary_and_table_are_the_cli_outputs(solved, tmp_path):
    r = CliRunner().invoke(main, ["solve", *SETS, "--method", "penalty", "-o", str(tmp_path / "p")])
    assert r.exit_code == 0, r.output
    cli = json.loads((tmp_path / "p" / "summary.json").read_text())
    api = solved["penalty"].summary
    for key in ("liftoff_load_factor", "section_liftoff_load_factor", "min_sigma_n_pa", "reaction_force_n",
                "penalty_k", "dofs"):
        assert api[key] == cli[key], key
    csv = pd.read_csv(tmp_path / "p" / "contact.csv")
    np.testing.assert_allclose(csv["sigma_n_pa"].to_numpy(), solved["penalty"].table["sigma_n_pa"].to_numpy(),
                               rtol=1e-12)                 # contact.csv is written with pandas' default 16 digits
    assert "-0.0" not in (tmp_path / "p" / "summary.json").read_text()


def test_penetration_is_force_over_k_normal_and_none_with_lagrange(model, solved):
    assert solved["lagrange"].penetration(1.0)["penetration_m"].max() == 0.0
    pen = deckbridge.solve(model.with_overrides({"contact.penalty.k_normal": 1.0e10}), method="penalty")
    s, p = pen.sigma_n(1.0), pen.penetration(1.0)
    closed = (s["status"] == "closed").to_numpy()
    np.testing.assert_allclose(s["force_n"].to_numpy()[closed], 1.0e10 * p["penetration_m"].to_numpy()[closed],
                               rtol=1e-9)
    assert p["penetration_m"].max() > 0
    assert p["penetration_over_t"].max() == pytest.approx(p["penetration_m"].max() / 0.03, rel=1e-12)


def test_friction_table_carries_t_lambda_in_its_direction(model):
    res = deckbridge.solve(model.with_overrides({"contact.tangential": "friction", "contact.friction": 0.6}),
                           method="lagrange")
    f = res.friction
    last = f[(f["step"] == 2) & (f["increment"] == f.loc[f["step"] == 2, "increment"].max())]
    lam = float(last["load_factor"].iloc[0])
    a = math.radians(60.0)
    assert (last["fn_x_n"] + last["ft_x_n"]).sum() == pytest.approx(1.0e5 * lam * math.cos(a), rel=1e-6)
    assert (last["fn_y_n"] + last["ft_y_n"]).sum() == pytest.approx(1.0e5 * lam * math.sin(a), rel=1e-6)
    assert set(last["stick_status"]) >= {"stick", "open"}
    ws = res.wall_stress(0)             # a friction solve recovers its base wall too: it carries N (measured 4.2e-4
    assert (ws["szz_mean_pa"] * ws["area_m2"]).sum() == pytest.approx(-2.0e6, rel=2e-3)   # off: nodal sigma_zz


def test_plot_draws_the_table_and_paraview_writes_every_state(model, tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    res = deckbridge.solve(model.with_overrides({"outputs.vtu": True}), method="lagrange")
    ax = res.plot(1.0)
    line = ax.get_lines()[-1]
    np.testing.assert_allclose(line.get_ydata(), res.sigma_n_wall(1.0)["sigma_n_pa"].to_numpy() / 1e6, rtol=1e-12)
    paths = res.to_paraview(tmp_path / "pv")
    vtus = [p for p in paths if p.suffix == ".vtu"]
    assert len(vtus) == len(res.states) and (tmp_path / "pv" / "result.pvd").is_file()
    text = (tmp_path / "pv" / "result.pvd").read_text()
    assert all(p.name in text for p in vtus)
    mesh = meshio.read(vtus[-1])
    assert mesh.points.shape[0] == res.summary["dofs"] // 3


def test_compare_differences_are_those_of_the_two_tables(solved):
    comp = deckbridge.compare(solved["penalty"], solved["lagrange"])
    assert comp.load_factors[0] == 0.0 and 1.0 in comp.load_factors
    pair = comp.pairs(1.0).iloc[0]
    d = (solved[pair["b"].split("/")[-1]].sigma_n_wall(1.0) - solved[pair["a"].split("/")[-1]].sigma_n_wall(1.0))
    assert pair["max_abs_diff_pa"] == pytest.approx(float(d["sigma_n_pa"].abs().max()), rel=1e-9)
    on = comp.onsets.set_index(["label", "onset"])
    for lab in comp.labels:
        assert on.loc[(lab, "first_node"), "exact"] == solved[lab.split("/")[-1]].onsets.loc["first_node", "load_factor"]
    assert no_negative_zero(comp.discrepancy.select_dtypes(float).to_numpy())
    ax = comp.plot(1.0)
    assert len(ax.get_lines()) == 2


def test_run_writes_the_job_and_matches_solve_and_compare_of_its_folders(model, solved, tmp_path):
    res = deckbridge.run(model.with_overrides({"outputs.vtu": True}), out=tmp_path / "job")
    assert res.report.is_file()
    pv = res.lagrange.to_paraview(tmp_path / "pv")            # the job's series, copied
    assert len([p for p in pv if p.suffix == ".vtu"]) == len(res.lagrange.states)
    for m in ("penalty", "lagrange"):
        a, b = res.solutions()[m].summary, solved[m].summary
        assert a["liftoff_load_factor"] == b["liftoff_load_factor"]
        assert a["section_liftoff_load_factor"] == b["section_liftoff_load_factor"]
        pd.testing.assert_frame_equal(res.solutions()[m].sigma_n_wall(1.0), solved[m].sigma_n_wall(1.0), rtol=1e-12)
    for f in ("summary.json", "reference_lagrange/summary.json", "reference_penalty/summary.json"):
        assert "-0.0" not in (tmp_path / "job" / f).read_text(), f
        if f != "summary.json":                             # the reference summaries: one name per fact
            assert set(json.loads((tmp_path / "job" / f).read_text())) <= set(summary_keys.KEYS), f
    comp = deckbridge.compare(tmp_path / "job" / "reference_penalty", tmp_path / "job" / "reference_lagrange",
                              model=model)
    assert comp.pairs(1.0)["max_abs_diff_pa"].iloc[0] == pytest.approx(
        res.comparison.pairs(1.0)["max_abs_diff_pa"].iloc[0], rel=1e-12)


def test_liftoff_brackets_the_solvers_onset_and_is_the_cli_s(model, solved, tmp_path):
    lo = deckbridge.liftoff(model, tol=1e-3)
    for m in ("penalty", "lagrange"):
        exact = solved[m].onsets.loc["first_node", "load_factor"]
        row = lo.table.loc[m]
        assert row["bracket_low"] <= exact + 1e-12 and exact <= row["bracket_high"] + 1e-3
    assert lo.beam_theory == pytest.approx(model.beam_theory_liftoff(), rel=1e-12)
    r = CliRunner().invoke(main, ["liftoff", *SETS, "--tol", "1e-3", "-o", str(tmp_path / "lo")])
    assert r.exit_code == 0, r.output
    cli = json.loads((tmp_path / "lo" / "summary.json").read_text())
    for m in ("penalty", "lagrange"):
        assert lo.table.loc[m, "lambda_c"] == pytest.approx(cli[m]["lambda_c"], rel=1e-9)


def test_sweep_rel_diff_is_that_of_solve_at_the_same_k(model, tmp_path):
    fixed = model.with_overrides({"contact.penalty.k_tangent": 1.0e8})   # k_t fixed: Lagrange = solve's Lagrange
    sw = deckbridge.sweep(fixed, [1.0, 10.0], tmp_path / "sw", load_factors=[1.0], report=False)
    lag = deckbridge.solve(fixed, method="lagrange").sigma_n_wall(1.0)["sigma_n_pa"]
    t = sw.table[(sw.table["method"] == "penalty") & np.isclose(sw.table["load_factor"], 1.0)]
    for k in (1.0, 10.0):
        pen = deckbridge.solve(fixed, method="penalty", k_factor=k).sigma_n_wall(1.0)["sigma_n_pa"]
        row = t[t["k_factor"] == k].iloc[0]
        assert row["max_abs_diff_pa"] == pytest.approx(float((pen - lag).abs().max()), rel=1e-6)
        assert row["rel_diff"] == pytest.approx(float((pen - lag).abs().max()) / abs(lag.min()), rel=1e-6)
    assert (tmp_path / "sw" / "sweep.csv").is_file()
    assert len(sw.plot().get_lines()) == 1
