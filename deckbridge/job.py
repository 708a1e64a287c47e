"""The main job: decks, reference solver with both methods (one condensation), optional CalculiX,
comparison and report. Layout of the output folder DIR:

  DIR/decks/                 every deck of the model
  DIR/reference_penalty/     contact.csv, summary.json, result.vtu (reference solver, penalty)
  DIR/reference_lagrange/    the same with Lagrange multipliers
  DIR/ccx/                   CalculiX jobs and results (--with-ccx)
  DIR/report.html, sigma_n.png, discrepancy.csv, summary.json   the comparison
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import Callable

from .compare import compare_tables
from .mesh import build_mesh
from .model import Model
from .outdir import prepare
from .render import render_all
from .readers.reference import read_globals
from .report import write_report
from .results import SourceResult
from .solve import condense_model, solve_system, write_outputs

Echo = Callable[[str], None]


def run_job(model: Model, outdir: str | Path, with_ccx: bool = False, echo: Echo = print,
            ccx_timeout_s: float = 1800.0) -> dict:
    """Run the main job on ``model`` into ``outdir``; return {'report': path, 'summary': dict, ...}."""
    out = prepare(outdir)
    t0 = time.perf_counter()
    mesh = build_mesh(model)          # the one mesh of the job: decks, reference solver
    decks = render_all(model, out / "decks", mesh=mesh,
                       on_unsupported=lambda err: echo(f"decks: skipped the {err.dialect} {' '.join(err.reason.split())}"))
    echo(f"decks: {len(decks)} files in {out / 'decks'}")

    mesh, system = condense_model(model, mesh)
    echo(f"reference solver: {system.dofs} dofs, {system.n_contacts} contact rows, "
         f"condensed in {time.perf_counter() - t0:.1f} s")
    tables, origins, summaries = [], [], {}
    for method in ("penalty", "lagrange"):
        df, summary, sol = solve_system(model, mesh, system, method, recover=model.outputs.vtu)
        folder = out / f"reference_{method}"
        write_outputs(folder, model, system, sol, df, summary)
        lam = summary["liftoff_load_factor"]
        echo(f"reference {method}: liftoff at lambda = "
             + ("none" if lam is None else f"{lam:.4f} (theta {summary['liftoff_theta_deg']:.1f} deg)")
             + f", min sigma_n {summary['min_sigma_n_pa'] / 1e6:.2f} MPa")
        tables.append(SourceResult(df, str(folder), summary=summary, **read_globals(folder, [method])))
        origins.append(str(folder))
        summaries[method] = summary

    if with_ccx:
        from .dialects import DIALECTS
        from .readers import read
        calculix = DIALECTS["calculix"]      # its decks, its runner (ccx), its reader
        runner = calculix.run_module()
        ccx_dir = prepare(out / "ccx")
        for deck in calculix.decks_in(out / "decks", model.name):
            job = ccx_dir / deck.name
            shutil.copyfile(deck, job)
            echo(f"ccx: running {job.name}")
            run = runner.run(job, timeout_s=ccx_timeout_s,
                             progress=lambda line: line.lower().startswith("increment") and echo(f"  ccx {line}"))
            echo(f"ccx: {job.name} finished in {run.seconds:.1f} s")
            tables.append(read(job.with_suffix(".frd"), fmt=calculix.reader, model=model))
            origins.append(str(job))

    result = compare_tables(tables, origins=origins)
    paths = write_report(result, out, model=model)
    report = out / "report.html"
    echo(f"report: {report} ({time.perf_counter() - t0:.1f} s in all)")
    return {"report": report, "paths": paths, "reference": summaries, "comparison": result}
