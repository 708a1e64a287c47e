"""The penalty sweep and the report's verdict on a friction model (``contact.tangential: friction``).

The condensed system of a friction model is a ``reference_solver.FrictionSystem`` (normal and tangential
dofs retained, no springs: k_t lives in the friction law), which the sweep re-binds and ships to its
workers without the sparse factor. Checked against an independent run: the sweep's Lagrange reference is
``deckbridge solve --method lagrange`` of the same model (contact table to round-off, same onset), the
penalty error against it falls as k grows, a penalty case that does not converge is a failed case with its
reason (not a crash), and the verdict's numbers at each k-factor are the sweep's.
"""

from __future__ import annotations

import json

import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge import summary_keys as K
from deckbridge.cli import main
from deckbridge.model import load
from deckbridge.studies.verdict import penalty_verdict

FRICTION = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=4", "contact.friction=0.2",
            "contact.tangential=friction"]
KS = (1.0, 10.0, 100.0, 1000.0)


def _sets(overrides):
    return [x for s in overrides for x in ("--set", s)]


@pytest.fixture(scope="module")
def friction_sweep(tmp_path_factory):
    """``deckbridge sweep`` of the friction model on two forked workers (the split strategy: each worker
    gets the condensed friction system without its factor); (summary, console output, study folder)."""
    out = tmp_path_factory.mktemp("friction") / "sweep"
    res = CliRunner().invoke(main, ["sweep", *_sets(FRICTION), "--k-factors", ",".join(f"{k:g}" for k in KS),
                                    "--workers", "2", "-o", str(out)])
    assert res.exit_code == 0, res.output + res.stderr
    return json.loads((out / "summary.json").read_text()), res.output, out


def test_friction_sweep_error_falls_with_k_against_the_lagrange_solve(friction_sweep, tmp_path):
    summary, console, out = friction_sweep
    mesh = summary["meshes"][0]
    assert mesh["lagrange"].get("error") is None
    rows = {d["k_factor"]: d for d in mesh["penalty"]}
    assert sorted(rows) == list(KS)
    ok = [rows[k] for k in KS if not rows[k].get("error")]
    assert [d["k_factor"] for d in ok][:3] == [1.0, 10.0, 100.0]
    errs = [d["max_rel_diff"] for d in ok]
    assert all(b < 0.5 * a for a, b in zip(errs, errs[1:])), errs     # measured 36 %, 10 %, 1.5 %
    assert errs[0] > 0.2 and rows[100.0]["max_rel_diff"] < 0.03
    for d in mesh["penalty"]:               # a case that did not converge: failed, with its reason, on the console
        if d.get("error"):
            assert "penalty" in d["error"] and d["reproduces"] is False
            assert f"{d['k_factor']:g}  failed: {d['error']}" in console

    # the reference is the plain Lagrange solve of the same model (friction: no springs to make rigid)
    res = CliRunner().invoke(main, ["solve", *_sets(FRICTION), "--method", "lagrange", "-o", str(tmp_path / "lag")])
    assert res.exit_code == 0, res.output + res.stderr
    solved = pd.read_csv(tmp_path / "lag" / "contact.csv")
    stored = pd.read_csv(out / "cases" / f"{mesh['lagrange']['case_id']}.csv")
    assert len(stored) == len(solved) and (stored["node"].to_numpy() == solved["node"].to_numpy()).all()
    peak = solved["sigma_n_pa"].abs().max()
    assert (stored["sigma_n_pa"] - solved["sigma_n_pa"]).abs().max() <= 1e-9 * peak
    lam = json.loads((tmp_path / "lag" / "summary.json").read_text())["liftoff_load_factor"]
    assert mesh["lagrange"]["liftoff_load_factor"] == pytest.approx(lam, rel=1e-9)
    assert summary["lagrange_reference"].startswith("Coulomb friction with exact stick")


def test_friction_verdict_gives_the_sweeps_numbers(friction_sweep):
    summary, _, _ = friction_sweep
    rows = {d["k_factor"]: d for d in summary["meshes"][0]["penalty"]}
    v = penalty_verdict(load(None, FRICTION))
    assert v["lagrange"]["liftoff_load_factor"] == pytest.approx(
        summary["meshes"][0]["lagrange"]["liftoff_load_factor"], rel=1e-9)
    seen = 0
    for r in v["evaluated"]:
        d = rows.get(r["k_factor"])
        if d is None:
            continue
        seen += 1
        assert bool(r.get("error")) == bool(d.get("error")), r["k_factor"]
        assert r["reproduces"] == d["reproduces"], r["k_factor"]
        if not d.get("error"):
            assert r["max_rel_diff"] == pytest.approx(d["max_rel_diff"], rel=1e-6), r["k_factor"]
    assert seen >= 3
    assert v["model_penalty"]["converged"] is False and v["model_penalty"]["max_rel_diff"] > 0.2


def test_sweep_console_table_has_the_summarys_onset_and_reproduces_columns(friction_sweep):
    """The console's per-k table carries summary.json's onset_rel_diff (in %) and reproduces, under those names."""
    summary, console, _ = friction_sweep
    lines = console.splitlines()
    head = next(i for i, ln in enumerate(lines) if ln.split()[:1] == ["k-factor"])
    assert lines[head].split()[-3:] == [K.ONSET_REL_DIFF, "%", K.REPRODUCES]
    rows = {float(ln.split()[0]): ln.split() for ln in lines[head + 1:head + 1 + len(KS)]}
    lag = summary["meshes"][0]["lagrange"]["liftoff_load_factor"]
    checked = 0
    for d in summary["meshes"][0]["penalty"]:
        if d.get("error"):
            continue
        *_, onset, rep = rows[d["k_factor"]]
        assert float(onset) == pytest.approx(abs(d["liftoff_load_factor"] - lag) / lag * 100, abs=0.006)
        assert float(onset) == pytest.approx(d[K.ONSET_REL_DIFF] * 100, abs=0.006)
        assert rep == ("yes" if d[K.REPRODUCES] else "no")
        checked += 1
    assert checked >= 3
