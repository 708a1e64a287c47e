"""The main job end to end on a small model, with CalculiX: every source against N / A in step 1."""

import json

import numpy as np
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
