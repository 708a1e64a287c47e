"""The augmented Lagrangian through deckbridge (issue 24): the one solve entry, the method registry, the CLI.

Anchors: the exact Lagrange solution of the same model (the augmented answer must not depend on k), at
every load factor of the path, on a coarse default JAR and on a held-out geometry (R = 1.3 m, H = 1.8 m,
t = 15 mm, a cone; and on four pads); its penetration within its tolerance.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

import reference_solver as rs
from deckbridge.cli import main
from deckbridge.methods import METHODS, NAMES
from deckbridge.model import load
from deckbridge.solve import bind, condense_model, solve_bound, solve_system

COARSE = ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]
HELD_OUT = ["geometry.radius=1.3", "geometry.height=1.8", "geometry.thickness=0.015", "geometry.top_radius=1.1",
            "mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=1"]
PADS = HELD_OUT + ["contact.pads={count: 4, width_deg: 30, first_deg: 0}"]


@pytest.mark.parametrize("overrides", [COARSE, HELD_OUT, PADS], ids=["default", "held_out_cone", "held_out_pads"])
def test_augmented_equals_lagrange_at_every_load_factor_for_any_k(overrides):
    model = load(None, overrides)
    mesh, system = condense_model(model)
    lag, lsum, _ = solve_system(model, mesh, system, "lagrange", recover=False)
    peak = lag["sigma_n_pa"].abs().max()
    assert lsum["liftoff_load_factor"] is not None
    for kf in (0.1, 1.0, 10.0, 100.0):
        aug, asum, sol = solve_system(model, mesh, system, "augmented", kf, recover=False)
        assert (aug["load_factor"].to_numpy() == lag["load_factor"].to_numpy()).all()
        assert np.abs(aug["sigma_n_pa"].to_numpy() - lag["sigma_n_pa"].to_numpy()).max() <= 1e-6 * peak
        assert asum["liftoff_load_factor"] == pytest.approx(lsum["liftoff_load_factor"], rel=1e-9)
        au = asum["augmented"]
        assert au["penetration_m"] <= au["penetration_tol_m"] and au["augmentations"] >= sol.step.size - 2
        assert asum["penalty_k"]["k_factor"] == kf


def test_one_solve_entry_binds_the_springs_once():
    model = load(None, COARSE + ["contact.penalty.k_tangent=follow"])
    mesh, system = condense_model(model)
    kf, bound = bind(model, system, "penalty", 10.0)
    assert bound is not system and bound.info["spring_factor"] == 10.0
    assert bind(model, bound, "penalty", 10.0)[1] is bound              # bound again: no second dense solve
    df, _, sol, used = solve_bound(model, mesh, bound, kf, "penalty", recover=False)
    assert used is bound
    direct, _, _ = solve_system(model, mesh, system, "penalty", 10.0, recover=False)
    assert np.array_equal(df["sigma_n_pa"].to_numpy(), direct["sigma_n_pa"].to_numpy())
    assert bind(model, bound, "augmented", 10.0)[1].info.get("spring_factor", 1.0) == 1.0   # exact: as built


def test_the_method_registry_is_the_solvers_list():
    assert NAMES == rs.METHODS
    assert [m for m in NAMES if METHODS[m].uses_k] == ["penalty", "augmented"]
    assert all(METHODS[m].algorithms == rs.LAWS[m].algorithms for m in NAMES)


def test_cli_solve_and_liftoff_accept_augmented(tmp_path):
    runner = CliRunner()
    sets = [a for s in COARSE for a in ("--set", s)]
    r = runner.invoke(main, ["solve", *sets, "--method", "augmented", "--k-factor", "10", "-o", str(tmp_path / "a"),
                             "--set", "outputs.vtu=false"])
    assert r.exit_code == 0, r.output
    assert "augmentations" in r.output
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert summary["method"] == "augmented" and summary["augmented"]["penetration_m"] <= 1e-9
    r = runner.invoke(main, ["liftoff", *sets, "--method", "augmented", "--tol", "1e-4"])
    assert r.exit_code == 0, r.output
    lag = runner.invoke(main, ["liftoff", *sets, "--method", "lagrange", "--tol", "1e-4"])
    assert "augmented (k x 1)" in r.output
    assert float(r.output.splitlines()[1].split()[4]) == pytest.approx(float(lag.output.splitlines()[1].split()[1]),
                                                                       abs=1e-4)


def test_sweep_with_augmented_gives_a_flat_curve_against_k(tmp_path):
    from deckbridge.studies.sweep import run_sweep
    model = load(None, COARSE)
    out = run_sweep(model, [0.1, 10.0], tmp_path / "sweep", progress=False, report=False, augmented=True)
    m = out["summary"]["meshes"][0]
    pen = [d["max_rel_diff"] for d in m["penalty"]]
    aug = [d["max_rel_diff"] for d in m["augmented"]]
    assert max(aug) <= 1e-6 and min(pen) > 1e-2                     # penalty hangs on k, augmented does not
    assert [d["liftoff_load_factor"] for d in m["augmented"]] == pytest.approx(
        [m["lagrange"]["liftoff_load_factor"]] * 2, rel=1e-6)


def test_run_accepts_augmented_as_a_reference_method(tmp_path):
    from deckbridge.job import run_job
    model = load(None, COARSE + ["outputs.vtu=false"])
    run_job(model, tmp_path / "run", echo=lambda line: None, methods=("lagrange", "augmented"))
    lag = json.loads((tmp_path / "run" / "reference_lagrange" / "summary.json").read_text())
    aug = json.loads((tmp_path / "run" / "reference_augmented" / "summary.json").read_text())
    assert aug["method"] == "augmented" and aug["augmented"]["augmentations"] > 0
    assert aug["liftoff_load_factor"] == pytest.approx(lag["liftoff_load_factor"], rel=1e-6)
    assert aug["min_sigma_n_pa"] == pytest.approx(lag["min_sigma_n_pa"], rel=1e-6)


def test_augmented_with_friction_where_it_converges():
    """Friction (24 x 6 x 2, mu = 0.2) at k x 100: step 1 equals the exact (semi-smooth Newton) Lagrange
    friction to round-off; along the path 6.7e-4 of the peak at lambda = 0.25 and 2e-8 at lambda = 1 (measured:
    the augmented friction iterations are not the Lagrange ones, and stick states can differ in between).
    At k x 1 they do not converge and say so in one line."""
    model = load(None, ["mesh.n_theta=24", "mesh.n_z=6", "mesh.n_r=2", "contact.friction=0.2",
                        "contact.tangential=friction"])
    mesh, system = condense_model(model)
    lag = rs.solve_path(system, "lagrange", increments=4, recover=False, liftoff_surface="table")
    aug = rs.solve_path(system, "augmented", 100.0, increments=4, recover=False, liftoff_surface="table")
    peak = np.abs(lag.force).max()
    err = np.abs(aug.force - lag.force).max(axis=1) / peak
    assert err[0] <= 1e-9 and err.max() <= 1e-3 and err[-1] <= 1e-6
    assert aug.augmentations[2:].min() >= 1 and aug.penetration.max() <= 1e-9
    with pytest.raises(rs.ReferenceSolverError):
        rs.solve_path(system, "augmented", 1.0, increments=4, recover=False)
