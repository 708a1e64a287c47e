"""ARCHITECTURE.md's "Add a dialect" checklist followed by a throw-away dialect, registered only inside this test.

The dialect "toy" has each part the checklist names: a template folder, a renderer (``write``), a record
(:class:`deckbridge.dialects.Dialect`) added to :data:`deckbridge.dialects.DIALECTS`, a reader (``read`` and
``detect``) and a runner. Its "solver" is the closed form of step 1 (N alone on a rigid table: every table node
at sigma_N = -N / A, A the sum of the nodes' tributary areas). With nothing else touched, the renderer, the
CLI's ``decks``, the readers, and the job (``run_job(solvers=["toy"])``: decks, run, read, compare, report) pick
it up; its numbers are checked against the closed form and the reference solver's step 1.
"""

import dataclasses
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from click.testing import CliRunner

from deckbridge import readers
from deckbridge.cli import main
from deckbridge.dialects import DIALECTS, Dialect, formats
from deckbridge.job import run_job
from deckbridge.model import load
from deckbridge.numbering.skirt import mesh_node_ids
from deckbridge.readers._checks import checked
from deckbridge.render import render_all
from deckbridge.render._env import deck_paths, render
from deckbridge.results import with_forces

SMALL = ["mesh.n_theta=16", "mesh.n_z=4", "mesh.n_r=1", "outputs.vtu=false"]
TEMPLATE = """# toy deck of {{ name }}: N = {{ n }} N; rows: node theta_deg r z area_m2
{% for row in rows %}{{ row }}
{% endfor %}"""


def write(model, mesh, outdir):            # checklist: render.py
    me = DIALECTS["toy"]
    (path,) = deck_paths(me, model.name, outdir)
    t = mesh.table
    rows = [f"{i} {th!r} {r!r} {z!r} {a!r}" for i, th, r, z, a in
            zip(mesh_node_ids(mesh, t.nodes), t.theta_deg, t.r, t.z, t.area)]
    path.write_text(render(me.templates, "toy.txt.j2", name=model.name, n=repr(float(model.loads.N)), rows=rows))
    return [path]


def run(deck, timeout_s, progress=None):    # checklist: runner.py (its "solver": the closed form of step 1)
    lines = Path(deck).read_text().splitlines()
    n = float(lines[0].split("N = ")[1].split()[0])
    rows = np.array([[float(x) for x in ln.split()] for ln in lines[1:] if ln.strip()])
    out = Path(deck).with_suffix(".toyres")
    pd.DataFrame({"node": rows[:, 0].astype(int), "theta_deg": rows[:, 1], "r": rows[:, 2], "z": rows[:, 3],
                  "area_m2": rows[:, 4], "sigma_n_pa": -n / rows[:, 4].sum()}).to_csv(out, index=False)
    return out


def detect(path):                           # checklist: reader.py (detect and read)
    return Path(path).suffix == ".toyres"


@checked("never")                           # step 1 only: no completeness check
def read(path, model=None):
    r = pd.read_csv(path)
    df = pd.DataFrame({"source": "toy", "method": "linear", "step": 1, "increment": 1, "load_factor": 0.0,
                       "node": r["node"], "surface": "table", "theta_deg": r["theta_deg"], "z": r["z"], "r": r["r"],
                       "sigma_n_pa": r["sigma_n_pa"], "gap_m": 0.0, "status": "closed"})
    return with_forces(df, r["area_m2"].to_numpy())


RECORD = Dialect(name="toy", package=__name__, renderer=f"{__name__}:write", templates="toy", reader="toy_res",
                 reader_module=__name__, source="toy", decks=("{name}_toy.txt",),
                 purpose="a throw-away dialect of tests/test_add_dialect.py", runner=f"{__name__}:run")


@pytest.fixture()
def toy(tmp_path, monkeypatch):
    """The record registered for this test only, its template folder outside the package (absolute)."""
    folder = tmp_path / "templates_toy"
    folder.mkdir()
    (folder / "toy.txt.j2").write_text(TEMPLATE)
    rec = dataclasses.replace(RECORD, templates=str(folder))
    monkeypatch.setitem(DIALECTS, "toy", rec)
    return rec


def test_a_throw_away_dialect_needs_only_its_record_and_parts(toy, tmp_path):
    model = load(None, SMALL)
    # rendered by render_all and by the CLI (decks --dialect toy)
    (deck,) = render_all(model, tmp_path / "decks", names=["toy"])
    assert deck.name == "JAR_toy.txt"
    res = CliRunner().invoke(main, ["decks", *sum((["--set", s] for s in SMALL), []), "-o", str(tmp_path / "cli"),
                                    "--dialect", "toy"])
    assert res.exit_code == 0, res.output
    assert (tmp_path / "cli" / "JAR_toy.txt").read_text() == deck.read_text()
    # its results are a format: detected, read into the tidy table
    assert "toy_res" in formats()
    result = toy.run(deck, timeout_s=10)
    assert readers.detect(result) == "toy_res"
    table = readers.read(result, model=model)
    np.testing.assert_allclose(table.force_n.sum(), model.loads.N, rtol=1e-12)      # force balance
    # the job runs it through its record, compares it with the reference solver and reports it
    out = tmp_path / "job"
    run_job(model, out, solvers=["toy"], echo=lambda s: None)
    assert (out / "toy" / "JAR_toy.toyres").is_file() and (out / "report.html").is_file()
    summary = json.loads((out / "summary.json").read_text())
    first = next(c for c in summary["comparisons"] if abs(c["load_factor"]) < 1e-12)
    peaks = {k: v["peak_compression_pa"] for k, v in first["sources"].items()}
    want = -model.loads.N / table.area_m2.sum()
    assert peaks["toy/linear"] == pytest.approx(want, rel=1e-12)
    assert peaks["reference/lagrange"] == pytest.approx(want, rel=0.02)
