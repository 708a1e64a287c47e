"""The quickstart notebook (docs/notebooks/quickstart.ipynb) runs, in under 15 lines of code, and gives the
numbers of the command line (issue 25).

The notebook is executed by nbclient in a fresh kernel; a probing cell appended here (not saved) prints what
the notebook computed as JSON. Truths: ``deckbridge solve`` run on the same model (its YAML written from the
notebook's model) for each method: every entry of its summary.json (timings aside) and the through-wall
sigma_N at lambda = 1 computed here from its contact.csv as -Sum force / Sum area per azimuth.
"""

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge.cli import main

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NOTEBOOK = Path(__file__).resolve().parents[1] / "docs" / "notebooks" / "quickstart.ipynb"
PROBE = """import json
print("PROBE" + json.dumps({"model": model.to_dict(),
                            "summary": {m: r.summary for m, r in results.items()},
                            "sigma_mpa": {m: {"theta": sigma.index.tolist(), "value": sigma[m].tolist()} for m in sigma},
                            "lines": [list(map(float, ln.get_ydata())) for ln in ax.get_lines()]}))"""
TIMINGS = ("timings_s", "wall_time_s")


@pytest.fixture(scope="module")
def executed(tmp_path_factory):
    nb = nbformat.read(NOTEBOOK, as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert sum(len(c.source.splitlines()) for c in code) < 15       # the acceptance: under 15 lines
    nb.cells.append(nbformat.v4.new_code_cell(PROBE))
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(tmp_path_factory.mktemp("nb"))}}).execute()
    outs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outs if o.get("output_type") == "error"]
    text = "".join(o.get("text", "") for o in nb.cells[-1].outputs if o.get("output_type") == "stream")
    assert any(o.get("output_type") == "display_data" and "image/png" in o.get("data", {}) for o in outs)  # the plot
    return json.loads(text[text.index("PROBE") + 5:])


@pytest.mark.parametrize("method", ["penalty", "lagrange"])
def test_notebook_numbers_are_the_cli_summary(executed, method, tmp_path):
    model_yaml = tmp_path / "model.yaml"
    import yaml
    model_yaml.write_text(yaml.safe_dump(executed["model"], sort_keys=False))
    r = CliRunner().invoke(main, ["solve", str(model_yaml), "--method", method, "-o", str(tmp_path / "out")])
    assert r.exit_code == 0, r.output
    cli = json.loads((tmp_path / "out" / "summary.json").read_text())
    nb = executed["summary"][method]
    assert set(nb) == set(cli)
    for key in set(cli) - set(TIMINGS):
        assert nb[key] == pytest.approx(cli[key], rel=1e-12, abs=1e-9) if isinstance(cli[key], float) \
            else nb[key] == cli[key], key
    assert cli["liftoff_load_factor"] is not None and 0.4 < cli["liftoff_load_factor"] < 0.8

    # sigma_N through the wall at lambda = 1 from contact.csv, computed here
    df = pd.read_csv(tmp_path / "out" / "contact.csv")
    last = df[(df["surface"] == "table") & (df["step"] == 2) & np.isclose(df["load_factor"], 1.0)]
    last = last[last["increment"] == last["increment"].max()]
    g = last.groupby(last["theta_deg"].round(6))
    want = (-g["force_n"].sum() / g["area_m2"].sum()).sort_index() / 1e6
    got = executed["sigma_mpa"][method]
    np.testing.assert_allclose(got["theta"], want.index.to_numpy(), atol=1e-6)
    np.testing.assert_allclose(got["value"], want.to_numpy(), rtol=1e-9, atol=1e-9)
    assert not any(v == 0 and np.signbit(v) for v in got["value"])          # no -0.0
    # the plot draws these numbers (penalty first, then lagrange)
    np.testing.assert_allclose(executed["lines"][["penalty", "lagrange"].index(method)], got["value"], rtol=1e-12)
