"""The main job: decks, reference solver with both methods (one condensation), optional CalculiX,
comparison and report. Layout of the output folder DIR:

  DIR/decks/                 every deck of the model
  DIR/reference_penalty/     contact.csv, summary.json, result.vtu, result.pvd + result_NNN.vtu, wall_stress.csv
                             (reference solver, penalty)
  DIR/reference_lagrange/    the same with Lagrange multipliers
  DIR/reference_augmented/   the same with the augmented Lagrangian (when asked: ``methods``)
                             (with contact.tangential: friction also friction.csv, deckbridge/friction_table.py)
  DIR/<run folder>/          with ``solvers``: each dialect's jobs and results, run by its record's runner
                             (CalculiX: DIR/ccx/, plus <job>.pvd + <job>_NNN.vtu; MYSTRAN: DIR/mystran/)
  DIR/report.html, sigma_n.png, discrepancy.csv, summary.json   the comparison

The job is all or nothing (:func:`deckbridge.outdir.replacing`): the previous run's entries are set aside
first; a failed or interrupted job (Ctrl-C, SIGTERM: ccx is stopped) leaves DIR as it was, a successful one
removes what the previous run wrote and this one did not (a stale ``ccx/``). Other files in DIR stay.
A dialect is run through its record (:class:`deckbridge.dialects.Dialect`: ``run_check``, ``runner``, its
reader, ``wall_reader``, ``series_writer``), never by its name; the mesh is built once and passed on.
"""

from __future__ import annotations

import functools
import shutil
import time
from pathlib import Path
from typing import Callable, Sequence

from reference_solver.recover import path_fields

from . import summary_keys as K
from .compare import compare_tables
from .compare.onsets import describe
from .compare.ring_lines import ring_line_text
from .dialects import DIALECTS
from .friction_table import friction_table
from .methods import LAGRANGE, NAMES, PENALTY
from .mesh import build_mesh
from .model import Model
from .onset_basis import basis_check
from .outdir import prepare, replacing
from .render import render_all
from .readers import read
from .readers.reference import solution_globals
from .reference_dual import dual_lagrange, mortar_series, wants_mortar_dual
from .reference_f2f import f2f_series, wants_f2f
from .studies.verdict import write_report_with_verdict
from .report.caveats import reference_caveats
from .results import SourceResult
from .solve import check_solvable, condense_model, result_mesh, solve_system, write_outputs
from .wall_stress import reference_section_onset, reference_wall, write_wall

Echo = Callable[[str], None]
RUN_METHODS = (PENALTY, LAGRANGE)                     # the reference solves of a job unless told otherwise


def layout() -> tuple[str, ...]:
    """What a job writes into DIR (set aside by a re-run): every method's reference folder and every runnable
    dialect's run folder included."""
    return ("decks", *(f"reference_{m}" for m in NAMES),
            *sorted({d.folder for d in DIALECTS.values() if d.runner}),
            "report.html", "sigma_n.png", "discrepancy.csv", "summary.json")


def run_job(model: Model, outdir: str | Path, with_ccx: bool = False, echo: Echo = print,
            ccx_timeout_s: float = 1800.0, solvers: Sequence[str] = (),
            methods: tuple[str, ...] = RUN_METHODS) -> dict:
    """Run the main job on ``model`` into ``outdir``, all or nothing; return {'report': path, ...}.
    ``solvers``: dialects whose solver runs on their decks too (``with_ccx``: calculix among them);
    ``ccx_timeout_s``: the time limit of each of their jobs [s]; ``methods``: the reference solves (method
    names of :mod:`deckbridge.methods`). A dialect that cannot run the model is refused (DeckUnsupported)
    before any work."""
    chosen = [DIALECTS[n] for n in dict.fromkeys([*solvers, *(["calculix"] if with_ccx else [])])]
    no_runner = [d.name for d in chosen if not d.runner]
    if no_runner:
        from .errors import DeckbridgeError
        raise DeckbridgeError(f"`solvers` = {no_runner[0]!r}: deckbridge runs no solver for this dialect "
                              f"(runnable: {', '.join(n for n, d in sorted(DIALECTS.items()) if d.runner)})")
    for d in chosen:
        d.check_run(model)
    t0 = time.perf_counter()
    mesh = build_mesh(model)          # the one mesh of the job: decks, reference solver
    check_solvable(model, mesh)       # refused before anything is written
    with replacing(outdir, "run", layout()) as out:
        return _job(model, out, mesh, chosen, echo, ccx_timeout_s, methods, t0)


def _job(model: Model, out: Path, mesh, chosen: list, echo: Echo, timeout_s: float, methods, t0: float) -> dict:
    decks = render_all(model, out / "decks", mesh=mesh,
                       on_unsupported=lambda exc: echo(exc.note()))
    echo(f"decks: {len(decks)} files in {out / 'decks'}")

    mesh, system = condense_model(model, mesh)
    echo(f"reference solver: {system.dofs} dofs, {system.n_contacts} contact rows, "
         f"condensed in {time.perf_counter() - t0:.1f} s")
    tables, origins, summaries = [], [], {}
    solve_dual = functools.cache(lambda: dual_lagrange(model, mesh, system))   # once: onsets, ccx/mortar
    for method in methods:
        df, summary, sol = solve_system(model, mesh, system, method, recover=False)
        folder = out / f"reference_{method}"
        lam_s, th_s = reference_section_onset(system, mesh, sol)
        summary[K.SECTION_LIFTOFF_LOAD_FACTOR], summary[K.SECTION_LIFTOFF_THETA_DEG] = lam_s, th_s
        summary["caveats"] = reference_caveats(model, mesh, system, sol)
        basis_warning = basis_check(model, mesh, system, summary, solve_dual)   # 8-/6-node faces: hat vs dual onsets
        if basis_warning:
            echo(basis_warning)
        U = path_fields(system, sol)             # the one recovery of every row: wall, VTUs, the report's globals
        fric = friction_table(df, sol, model.contact.friction, system.problem.contact_normals)   # None: no friction
        write_outputs(folder, model, system, sol, df, summary, mesh, U=U, fric=fric)
        wall = reference_wall(system, mesh, sol, U)
        write_wall(folder, wall)
        vtu = result_mesh(system.problem, sol, U) if model.outputs.vtu else None
        tables.append(SourceResult(df, str(folder), summary=summary, wall=wall, friction=fric,
                                   **solution_globals(vtu, method)))
        origins.append(str(folder))
        summaries[method] = summary
    if wants_f2f(model, chosen, out / "decks"):   # ccx/f2f's partner: the face-integrated penalty (issue 24)
        origin = f"{out / 'reference_penalty'} (face-integrated)"
        tables.append(f2f_series(model, mesh, system, origin))
        origins.append(origin)
    if wants_mortar_dual(model, mesh, chosen, out / "decks"):   # ccx/mortar's partner: ccx's multiplier basis
        origin = f"{out / 'reference_lagrange'} (ccx's dual basis)"
        tables.append(mortar_series(model, mesh, system, origin, solve_dual()))
        origins.append(origin)

    for d in chosen:                            # its decks, its runner, its reader, its wall and series
        run_dir = prepare(out / d.folder)
        for deck in d.decks_in(out / "decks", model.name):
            job = run_dir / deck.name
            shutil.copyfile(deck, job)
            echo(f"{d.source}: running {job.name}")
            t_run = time.perf_counter()
            result = d.run(job, timeout_s=timeout_s,
                           progress=lambda line: line.lower().startswith(("increment", "terminated"))
                           and echo(f"  {d.source} {line}"))
            echo(f"{d.source}: {job.name} finished in {time.perf_counter() - t_run:.1f} s")
            table = read(result, fmt=d.reader, model=model, mesh=mesh)
            tables.append(SourceResult(table, str(job), wall=d.wall(result, model, mesh),
                                       ring_lines=d.ring_lines(result, model, mesh)))
            if model.outputs.vtu:       # ParaView series (CalculiX: <job>.pvd + <job>_NNN.vtu)
                d.write_series(job, model, run_dir, mesh, table)
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
    for line in ring_line_text(result):         # ccx f2f on 8-/6-node faces: the exact comparison beside sigma_N
        echo(line)
    paths = write_report_with_verdict(result, out, model=model, extra={"condensed": (mesh, system)})  # reused
    report = out / "report.html"
    echo(f"report: {report} ({time.perf_counter() - t0:.1f} s in all)")
    return {"report": report, "paths": paths, "reference": summaries, "comparison": result}
