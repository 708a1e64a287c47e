"""The report's penalty verdict (deckbridge/studies/verdict.py) against a sweep run here and against direct
solves: its "converged" call is the sweep's, and the KA it gives, written as the model's own penalty,
reproduces Lagrange within the stated tolerance."""

from __future__ import annotations

import numpy as np
import pytest

from deckbridge.model import load
from deckbridge.studies.verdict import penalty_verdict
from deckbridge.solve import solve_model
from deckbridge.studies.sweep import run_sweep

TOL = 0.02
SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5"]
# held out: another radius, a thinner wall, a cone, a fixed k_t, loads that lift off before tipping
HELD_OUT = ["mesh.n_theta=20", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=5", "geometry.radius=1.0",
            "geometry.thickness=0.012", "geometry.height=1.5", "geometry.top_radius=0.9",
            "contact.penalty.k_tangent=2e8", "steps.lambda_max=0.7"]


def _wall_profile(table, lam):
    """sigma_N through the wall per azimuth at load factor ``lam`` (last state there) [Pa]: -sum F / sum A."""
    t = table[(table["surface"] == "table") & np.isclose(table["load_factor"], lam)]
    last = max(zip(t["step"], t["increment"]))
    t = t[(t["step"] == last[0]) & (t["increment"] == last[1])]
    g = t.groupby(t["theta_deg"].round(6))
    return -g["force_n"].sum() / g["area_m2"].sum()


@pytest.mark.parametrize("sets", [SMALL, HELD_OUT], ids=["default-small", "held-out-cone"])
def test_verdict_agrees_with_a_sweep_and_its_ka_reproduces_lagrange(sets, tmp_path):
    model = load(None, sets)
    v = penalty_verdict(model, tol=TOL)
    ks = [r["k_factor"] for r in v["evaluated"]]
    assert v["command"].split("--k-factors ")[1].split()[0] == ",".join(f"{k:g}" for k in ks)

    # the sweep over the k-factors the verdict names gives the same calls
    s = run_sweep(model, ks, tmp_path / "sweep", tol=TOL, progress=False, report=False)["summary"]
    per_k = {d["k_factor"]: d for d in s["meshes"][0]["penalty"]}
    for r in v["evaluated"]:
        assert per_k[r["k_factor"]]["reproduces"] == r["reproduces"], r["k_factor"]
        assert per_k[r["k_factor"]]["max_rel_diff"] == pytest.approx(r["max_rel_diff"], rel=1e-9, abs=1e-12)
    assert v["model_penalty"]["converged"] == per_k[1.0]["reproduces"]
    rec = v["recommended"]
    assert rec is not None and s["recommended_k_factor"] == rec["k_factor"]
    assert not v["model_penalty"]["converged"]          # alpha = 0.1 is not converged on either model
    assert v["model_penalty"]["penetration_over_t"] > 0.01 > rec["penetration_over_t"]

    # KA per node of the recommendation = k-factor x the mesh's k_c (SI deck: N/m)
    assert rec["unit"] == "N/m" and rec["alpha"] == pytest.approx(model.contact.penalty.alpha * rec["k_factor"])

    # written as the model's own penalty (alpha), solved directly: within TOL of Lagrange
    stiff = model.with_overrides({"contact.penalty.alpha": rec["alpha"]})
    assert penalty_verdict(stiff, tol=TOL)["model_penalty"]["converged"]
    again = run_sweep(stiff, [1.0], tmp_path / "stiff", tol=TOL, progress=False, report=False)["summary"]
    assert again["meshes"][0]["penalty"][0]["reproduces"] and again["recommended_k_factor"] == 1.0
    if model.contact.penalty.k_tangent is not None:     # fixed k_t: the plain Lagrange solve is the reference
        pen, ps = solve_model(stiff, "penalty")
        lag, ls = solve_model(model, "lagrange")
        for lam in (0.0, model.steps.lambda_max):
            a, b = _wall_profile(pen, lam), _wall_profile(lag, lam)
            assert (a - b).abs().max() <= TOL * abs(b.min()), lam
        assert abs(ps["liftoff_load_factor"] - ls["liftoff_load_factor"]) <= TOL * ls["liftoff_load_factor"]


def test_verdict_in_mm_gives_ka_in_n_per_mm():
    model = load(None, SMALL + ["units=mm"])
    v = penalty_verdict(model, tol=0.2)
    si = penalty_verdict(load(None, SMALL), tol=0.2)
    r, q = v["recommended"], si["recommended"]
    assert r["unit"] == "N/mm" and r["k_factor"] == q["k_factor"]
    assert r["ka_min"] == pytest.approx(q["ka_min"] * 1e-3, rel=1e-12)


@pytest.mark.ccx
def test_the_recommended_ka_written_into_the_ccx_penalty_deck_reproduces_lagrange(tmp_path):
    """The verdict's alpha written into the CalculiX node-to-surface penalty deck (its pressure-overclosure slope
    reproduces each node's KA = k-factor x k_c), run by ccx: sigma_N through the wall within TOL x the peak of the
    reference Lagrange at every increment in the small-strain range (lift / R <= 0.01), past liftoff included.
    Until the deck's R_n followed the stiffness (render.n2f_residual_tol) ccx stopped here at alpha >= 10 with
    'increment size smaller than minimum', iterating on the round-off residual of the zero-clearance stop springs."""
    from ccx_job import ccx_penalty_job

    from deckbridge.readers import read

    model = load(None, ["mesh.n_theta=24", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=7", "steps.lambda_max=0.7",
                        "geometry.radius=1.2", "geometry.thickness=0.012", "geometry.height=1.5",
                        "contact.penalty.k_tangent=2e8"])
    v = penalty_verdict(model, tol=TOL)
    assert not v["model_penalty"]["converged"]
    stiff = model.with_overrides({"contact.penalty.alpha": v["recommended"]["alpha"]})
    ccx = read(ccx_penalty_job(stiff, tmp_path).with_suffix(".frd"), fmt="calculix", model=stiff)
    lag, _ = solve_model(model, "lagrange")
    g = model.geometry
    compared = lifted = 0
    for lam in sorted(set(lag.load_factor.round(9))):
        if lam == 0.0:
            continue
        at = lag[np.isclose(lag.load_factor, lam) & (lag.step == 2) & (lag.surface == "table")]
        if at.gap_m.max() / (g.radius + g.thickness / 2) > 0.01:
            continue
        a, b = _wall_profile(ccx[ccx.step == 2], lam), _wall_profile(lag[lag.step == 2], lam)
        assert len(a) == len(b) == model.mesh.n_theta
        assert (a - b).abs().max() <= TOL * abs(b.min()), lam
        compared += 1
        lifted += int((at.status == "open").any())
    assert compared >= 4 and lifted >= 1
