"""The main job: decks, reference solver with both methods (one condensation), optional CalculiX,
comparison and report. Layout of the output folder DIR:

  DIR/decks/                 every deck of the model
  DIR/reference_penalty/     contact.csv, summary.json, result.vtu, result.pvd + result_NNN.vtu, wall_stress.csv
                             (reference solver, penalty)
  DIR/reference_lagrange/    the same with Lagrange multipliers
                             (with contact.tangential: friction also friction.csv, deckbridge/friction_table.py)
  DIR/ccx/                   CalculiX jobs and results, <job>.pvd + <job>_NNN.vtu (--with-ccx)
  DIR/report.html, sigma_n.png, discrepancy.csv, summary.json   the comparison

The job is all or nothing (:func:`deckbridge.outdir.replacing`): the previous run's entries are set aside
first; a failed or interrupted job (Ctrl-C, SIGTERM: ccx is stopped) leaves DIR as it was, a successful one
removes what the previous run wrote and this one did not (a stale ``ccx/``). Other files in DIR stay.
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import Callable

from . import summary_keys as K
from .compare import compare_tables
from .compare.onsets import describe
from .friction_table import read_friction
from .mesh import build_mesh
from .model import Model
from .outdir import prepare, replacing
from .paraview_ccx import write_ccx_series
from .render import render_all
from .readers.reference import read_globals
from .report import write_report
from .report.caveats import reference_caveats
from .results import SourceResult
from .solve import condense_model, solve_system, write_outputs
from .wall_stress import ccx_wall, reference_section_onset, reference_wall, write_wall

Echo = Callable[[str], None]
LAYOUT = ("decks", "reference_penalty", "reference_lagrange", "ccx", "report.html", "sigma_n.png",
          "discrepancy.csv", "summary.json")          # what a job writes into DIR (set aside by a re-run)


def run_job(model: Model, outdir: str | Path, with_ccx: bool = False, echo: Echo = print,
            ccx_timeout_s: float = 1800.0) -> dict:
    """Run the main job on ``model`` into ``outdir``, all or nothing; return {'report': path, ...}.
    ``with_ccx`` on a model the CalculiX decks cannot carry is refused (DeckUnsupported) before any work."""
    if with_ccx:
        from .render.calculix import check_supported
        check_supported(model)
    with replacing(outdir, "run", LAYOUT) as out:
        return _job(model, out, with_ccx, echo, ccx_timeout_s)


def _job(model: Model, out: Path, with_ccx: bool, echo: Echo, ccx_timeout_s: float) -> dict:
    t0 = time.perf_counter()
    mesh = build_mesh(model)          # the one mesh of the job: decks, reference solver
    decks = render_all(model, out / "decks", mesh=mesh,
                       on_unsupported=lambda exc: echo(exc.note()))
    echo(f"decks: {len(decks)} files in {out / 'decks'}")

    mesh, system = condense_model(model, mesh)
    echo(f"reference solver: {system.dofs} dofs, {system.n_contacts} contact rows, "
         f"condensed in {time.perf_counter() - t0:.1f} s")
    tables, origins, summaries = [], [], {}
    for method in ("penalty", "lagrange"):
        df, summary, sol = solve_system(model, mesh, system, method, recover=model.outputs.vtu)
        folder = out / f"reference_{method}"
        lam_s, th_s = reference_section_onset(system, mesh, sol)
        summary[K.SECTION_LIFTOFF_LOAD_FACTOR], summary[K.SECTION_LIFTOFF_THETA_DEG] = lam_s, th_s
        summary["caveats"] = reference_caveats(model, mesh, system, sol)
        write_outputs(folder, model, system, sol, df, summary, mesh)
        wall = reference_wall(system, mesh, sol)
        write_wall(folder, wall)
        tables.append(SourceResult(df, str(folder), summary=summary, wall=wall, friction=read_friction(folder),
                                   **read_globals(folder, [method])))
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
            wall = ccx_wall(job.with_suffix(".dat"), model, mesh)
            tables.append(SourceResult(read(job.with_suffix(".frd"), fmt=calculix.reader, model=model), str(job),
                                       wall=wall))
            if model.outputs.vtu:       # ParaView series <job>.pvd + <job>_NNN.vtu
                write_ccx_series(job, model, ccx_dir)
            origins.append(str(job))

    result = compare_tables(tables, origins=origins)
    for s in result.series:                     # the comparison's numbers, as summary.json and the report
        o = result.onsets[s.label]
        pk, node = result.primary.peaks.get(s.label), result.primary.node_peaks.get(s.label)
        echo(f"{s.label}: onset first node {describe(o['first_node'])}, whole section {describe(o['section'])}"
             + ("" if pk is None else f"; at lambda = {result.primary.load_factor:.4g} peak sigma_n "
                f"{pk[0] / 1e6:.1f} MPa through the wall")
             + ("" if node is None else f", {node[0] / 1e6:.1f} MPa at one node"))
        for pt in result.points:                # the checks that warn (definitions: deckbridge/quantities.py)
            ex = pt.extra.get(s.label, {})
            if ex.get("warn"):
                echo(f"  warning: lambda = {pt.load_factor:.4g}: base-wall sigma_zz equilibrium residual "
                     f"{ex['szz_resultant_residual']:.2%} (> 1 %)")
            if ex.get("open_tension_ratio", 0.0) > 0.01:
                echo(f"  warning: lambda = {pt.load_factor:.4g}: open gaps carry tension up to "
                     f"{ex['max_open_sigma_n_pa'] / 1e6:.3g} MPa ({ex['open_tension_ratio']:.1%} of the peak; kept)")
            if ex.get("free_penetration_warn"):
                echo(f"  warning: lambda = {pt.load_factor:.4g}: table node(s) {ex['free_penetration_nodes']} "
                     f"penetrate up to {ex['free_penetration_m'] * 1e3:.3g} mm with no contact force "
                     "(the solver's contact search missed them?)")
    paths = write_report(result, out, model=model, extra={"condensed": (mesh, system)})   # the verdict reuses them
    report = out / "report.html"
    echo(f"report: {report} ({time.perf_counter() - t0:.1f} s in all)")
    return {"report": report, "paths": paths, "reference": summaries, "comparison": result}
