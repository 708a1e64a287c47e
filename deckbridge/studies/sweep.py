"""The penalty sensitivity study: penalty at several k-factors (and meshes) against Lagrange.

``run_sweep(model, k_factors, outdir, ...)`` solves every case that the store under ``outdir``
lacks, storing each as it finishes, then measures every case against the Lagrange reference of its
mesh (:mod:`.metrics`) and writes, atomically:

  DIR/summary.json   the tables (per mesh and k) and the recommended k-factor (the smallest that reproduces
                     Lagrange, onset included, :mod:`.recommend`) as alpha and KA; deterministic: a
                     resumed study writes the same file as an uninterrupted one
  DIR/sweep.csv      one row per (mesh, case, compared load factor)
  DIR/quantities.csv the tidy table of the compared quantities per case at the claims' load factor
                     (case id, grid values, method, k-factor, load factor, quantity, theta or 'peak',
                     value, unit) and summary.json 'claims': the paper's claims judged (:mod:`.claims`)
  DIR/report.html    sigma_N(theta) of every k against Lagrange, metrics against k (log axes)
  DIR/run.json       this run only: cases computed / reused / failed, timings, executor
  DIR/cases/         the stored cases (see :mod:`.store`)

Cases are grouped by condense key (:attr:`.cases.MeshVariant.condense_key`): grid points differing only
in the penalty rule, the open ratio or the spring stiffness share one condensation, each case re-binding
its own contact and spring stiffness on it (:func:`.tasks.solve_case`). The Lagrange reference is the limit
k -> infinity of the penalty cases: with k_t following alpha the penalty springs scale with the k-factor
and the reference's are rigid; a fixed k_t is the same in both (:mod:`deckbridge.tangent_springs`). Base-wall sigma_zz needs the sparse factor: in process and with strategy
'mesh' it is recovered, with 'split' (condensation moved to other workers) only contact sigma_N is judged.

Execution: ``client=None`` runs in this process (with field recovery); a
:class:`~deckbridge.studies.local.LocalExecutor` condenses on a forked process and solves the cases on
worker processes forked after it (``deckbridge sweep`` uses it for one condensation: no cluster to start,
nothing sent, see :mod:`.local`); a ``dask.distributed.Client`` runs the cases on its cluster. On Dask,
strategy ``'split'`` (default) submits one condensation task per mesh and one task per case depending on
it, so the cases of a mesh spread over the workers; ``'mesh'`` submits one task per mesh that condenses
and solves its cases in turn (the local executor keeps the sparse factor with ``'mesh'``: wall sigma_zz
recovered). Only the client writes to disk. Measured on 2 cores with Dask (default JAR, 6 k-factors +
Lagrange): both give identical files; one mesh, the same time within the noise (4-5 s per command);
meshes n_theta = 36, 72, 144: 8.9 s (split) and 8.6 s (mesh), the condensations dominating. A condensed default mesh (288 contact rows) is about 2 MB to move to
another worker, 16 MB at n_theta = 240.
"""

from __future__ import annotations

import json
import math
import time
import uuid
from pathlib import Path
from typing import Callable

import pandas as pd
from tqdm import tqdm

from ..errors import DeckbridgeError
from ..methods import AUGMENTED, LAGRANGE, PENALTY
from ..model import Model
from ..outdir import prepare, staged
from .cases import OPEN_STIFFNESS, Case, mesh_variants, sweep_cases
from .local import LocalExecutor
from .claims import tidy_frame, variant_claims
from ..compare.series import series_of
from .metrics import VariantResult, monotone, rnd, variant_metrics
from .recommend import node_stiffness, overall_recommendation, variant_recommendation
from ..mesh import build_mesh
from .store import CaseStore
from .tasks import condense_or_error, condense_variant, solve_case, solve_or_error, solve_variant_batch

STRATEGIES = ("split", "mesh")
CSV_COLUMNS = ["mesh", "method", "k_factor", "load_factor", "what", "max_abs_diff_pa", "rel_diff",
               "theta_of_max_diff_deg", "rms_diff_pa", "liftoff_zone_iou", "peak_compression_pa",
               "peak_compression_theta_deg", "lagrange_peak_compression_pa", "within_tol",
               "liftoff_load_factor", "liftoff_theta_deg", "case_id"]


def check_options(k_factors, tol, open_stiffness, strategy, model: Model, load_factors=None) -> None:
    """Refuse bad options with one line, before anything is computed or written."""
    if not k_factors:
        raise DeckbridgeError("`k_factors`: give at least one penalty factor")
    if not (isinstance(tol, (int, float)) and math.isfinite(tol) and 0 < tol < 1):
        raise DeckbridgeError(f"`tol` = {tol!r}: must be a fraction in (0, 1), e.g. 0.02 for 2 %")
    if open_stiffness not in OPEN_STIFFNESS:
        raise DeckbridgeError(f"`open_stiffness` = {open_stiffness!r}: must be one of {', '.join(OPEN_STIFFNESS)}")
    if strategy not in STRATEGIES:
        raise DeckbridgeError(f"strategy = {strategy!r}: must be one of {', '.join(STRATEGIES)}")
    for lf in load_factors or []:
        if not (isinstance(lf, (int, float)) and 0 <= lf <= model.steps.lambda_max):
            raise DeckbridgeError(f"`load_factors` = {lf!r}: must be within [0, steps.lambda_max = "
                                  f"{model.steps.lambda_max:g}]")
    ratio = model.contact.penalty.open_ratio
    if open_stiffness == "fixed" and min(k_factors) <= ratio:
        raise DeckbridgeError(f"`k_factors`: {min(k_factors):g} with `open_stiffness` fixed would make the closed "
                              f"stiffness no larger than the open one (contact.penalty.open_ratio = {ratio:g})")


def _groups(cases: list[Case]) -> list[tuple[object, list[Case]]]:
    out: dict[str, tuple[object, list[Case]]] = {}
    for c in cases:
        out.setdefault(c.mesh.condense_key, (c.mesh, []))[1].append(c)
    return list(out.values())


def execute(todo: list[Case], store: CaseStore, run_id: str, client=None, strategy: str = "split",
            progress: bool = True, on_case_stored: Callable[[Case], None] | None = None,
            prebuilt: dict | None = None, meanwhile: Callable[[], object] | None = None) -> dict:
    """Solve the cases ``todo`` and store each as it finishes; returns {'computed', 'failed', ...}.

    ``prebuilt``: filled with case id -> :class:`.local.Prepared` for the cases whose table the local
    executor's workers serialised, read back and turned into a series (the text is what is stored).
    ``meanwhile``: work of the client (the report's imports) run by the local executor while a forked
    process condenses."""
    done, failed = [], []
    timings: dict[str, dict] = {}
    bar = tqdm(total=len(todo), desc="sweep cases", unit="case", disable=not progress or not todo, leave=False)

    def finish(case: Case, out=None, error: str | None = None):
        if error is None:
            df, summary, prov, *prep = out
            prov = dict(prov)
            store.put(case, df, summary, run_id, extra=prov, wall=prov.pop("wall", None),
                      text=prep[0].text if prep else None)
            if prep and prebuilt is not None:
                prebuilt[case.case_id] = prep[0]
            done.append(case.case_id)
            timings[case.case_id] = prov
        else:
            store.put_failed(case, error, run_id)
            failed.append(case.case_id)
        bar.update(1)
        bar.set_postfix_str(case.label if error is None else f"{case.label} failed")
        if on_case_stored is not None:
            on_case_stored(case)

    jobs = lambda cs: [(c.mesh.model.to_dict(), c.method, c.k_factor, c.open_stiffness) for c in cs]  # noqa: E731
    try:
        if client is None:
            for variant, cases in _groups(todo):
                md = variant.model.to_dict()
                try:
                    cond = condense_variant(md, light=False)
                except DeckbridgeError as exc:
                    for c in cases:
                        finish(c, error=str(exc))
                    continue
                for c in cases:
                    try:
                        res = solve_case(cond, c.mesh.model.to_dict(), c.method, c.k_factor, c.open_stiffness)
                    except DeckbridgeError as exc:
                        finish(c, error=str(exc))
                    else:
                        finish(c, res)
        elif isinstance(client, LocalExecutor):
            _execute_local(client, todo, strategy, jobs, finish, meanwhile)
        else:
            _execute_dask(client, todo, strategy, run_id, jobs, finish)
    finally:
        bar.close()
    return {"computed": done, "failed": failed, "timings": timings}


def _execute_local(local: LocalExecutor, todo, strategy, jobs, finish, meanwhile=None) -> None:
    """Each condense key condensed (on a forked process while this one runs ``meanwhile`` once), then its
    cases on forked workers (:mod:`.local`)."""
    for variant, cases in _groups(todo):
        try:
            cond = local.condense(variant.model.to_dict(), strategy == "split", meanwhile)
        except DeckbridgeError as exc:
            for c in cases:
                finish(c, error=str(exc))
            continue
        finally:
            meanwhile = None
        for i, r in local.solve(cond, jobs(cases), [c.label for c in cases]):
            if isinstance(r, DeckbridgeError):
                finish(cases[i], error=str(r))
            else:
                finish(cases[i], r)


def _execute_dask(client, todo, strategy, run_id, jobs, finish) -> None:
    from dask.distributed import as_completed

    futures = {}
    for variant, cases in _groups(todo):
        md = variant.model.to_dict()
        if strategy == "mesh":
            f = client.submit(solve_variant_batch, md, jobs(cases), key=f"batch-{variant.condense_key}-{run_id}")
            futures[f] = cases
        else:
            cf = client.submit(condense_or_error, md, key=f"condense-{variant.condense_key}-{run_id}")
            for c in cases:
                f = client.submit(solve_or_error, cf, c.mesh.model.to_dict(), c.method, c.k_factor, c.open_stiffness,
                                  key=f"case-{c.case_id}-{run_id}")
                futures[f] = [c]
    try:
        for f in as_completed(list(futures)):
            cases = futures.pop(f)
            try:
                res = f.result()
            except Exception as exc:        # a worker lost, a cluster gone: stop, keep what is stored
                msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
                raise DeckbridgeError(f"case {cases[0].case_id}: {type(exc).__name__}: {msg} "
                                      "(finished cases are stored; run the same command again to resume)") from None
            for c, r in zip(cases, res if strategy == "mesh" else [res]):
                if isinstance(r, DeckbridgeError):
                    finish(c, error=str(r))
                else:
                    finish(c, r)
    finally:
        if futures:
            client.cancel(list(futures))


def run_sweep(model: Model, k_factors: list[float], outdir: str | Path, meshes: list[dict] | None = None,
              tol: float = 0.02, load_factors: list[float] | None = None, open_stiffness: str = "scaled",
              client=None, strategy: str = "split", progress: bool = True,
              on_case_stored: Callable[[Case], None] | None = None, report: bool = True,
              grid: list[dict] | None = None, claim_load_factor: float | None = None, augmented: bool = False) -> dict:
    """Run (or resume) the sweep into ``outdir``; returns {'summary', 'run', 'paths', 'variants', 'claims'}.
    ``augmented``: also the augmented Lagrangian at every k-factor (summary 'augmented' per mesh: flat in k).

    ``grid``: points of other model keys (see :func:`.cases.parse_grid_options`); ``claim_load_factor``:
    the lambda at which the claims are judged (default min(1, steps.lambda_max))."""
    t0 = time.perf_counter()
    k_factors = sorted(set(float(k) for k in k_factors))
    check_options(k_factors, tol, open_stiffness, strategy, model, load_factors)
    lam = min(1.0, model.steps.lambda_max) if claim_load_factor is None else float(claim_load_factor)
    check_options(k_factors, tol, open_stiffness, strategy, model, [lam])
    variants = mesh_variants(model, meshes, grid)
    cases = sweep_cases(variants, k_factors, open_stiffness, augmented)
    prepare(outdir)
    store = CaseStore(outdir)
    run_id = uuid.uuid4().hex[:12]
    reused = [c.case_id for c in cases if store.has(c)]
    done = set(reused)
    todo = [c for c in cases if c.case_id not in done]
    t1 = time.perf_counter()
    read_back: dict[str, pd.DataFrame] = {}
    series: dict[str, object] = {}
    prebuilt: dict[str, object] = {}

    def stored(case: Case) -> None:
        """Read a case back from the store as soon as it is stored, and build its series: the client
        waits on the workers meanwhile, so the metrics below start with the work done."""
        try:
            rec = store.meta(case)
            pre = prebuilt.pop(case.case_id, None)
            if rec is not None and not rec.get("error"):
                if pre is not None and pre.series is not None:      # the stored text, read back on a worker
                    read_back[case.case_id], series[case.case_id] = pre.table, pre.series
                else:
                    read_back[case.case_id] = store.table(case)
                    series[case.case_id] = series_of(read_back[case.case_id], case.label)
        except Exception:          # noqa: BLE001  (left to the metrics below, which raise where they did)
            read_back.pop(case.case_id, None)
            series.pop(case.case_id, None)
        if on_case_stored is not None:
            on_case_stored(case)

    ex = execute(todo, store, run_id, client, strategy, progress, stored, prebuilt,
                 meanwhile=_import_report if report else None)
    t2 = time.perf_counter()

    records = {c.case_id: store.meta(c) for c in cases}
    missing = [cid for cid, r in records.items() if r is None]
    if missing:
        raise DeckbridgeError(f"{store.dir}: case {missing[0]} is not stored after the run (disk full or removed?)")
    if all(r.get("error") for r in records.values()):
        first = next(iter(records.values()))["error"]
        raise DeckbridgeError(f"every case failed; first: {first}")
    tables = {c.case_id: read_back[c.case_id] if c.case_id in read_back else store.table(c)
              for c in cases if not records[c.case_id].get("error")}
    of = lambda v: [c for c in cases if c.mesh is v]  # noqa: E731
    results = [variant_metrics(v, of(v), tables, records, tol, load_factors, series) for v in variants]
    summary = make_summary(model, variants, results, k_factors, tol, open_stiffness, load_factors)
    walls = {cid: store.wall(c) for c in cases if (cid := c.case_id) in tables}
    claims, qrows = [], []
    for v in variants:
        verdict, rows = variant_claims(v, of(v), tables, walls, records, lam, tol)
        claims.append(verdict)
        qrows += rows
    summary["claims"] = rnd(claims)
    summary["claims_definition"] = (
        "claim 1: penalty sigma > 0 in its lifted zones (every table node of the azimuth open) while Lagrange "
        "sigma <= 0 at every azimuth, at the state of step 2 nearest to lambda; claim 2: peak |sigma| over the "
        "azimuth falls as k grows (direction: falls / rises / non-monotone), and the k within tol x the Lagrange "
        "peak; '> 0' means above 1e-6 x the Lagrange peak; wall sigma_zz needs field recovery (in process or "
        "--strategy mesh)")
    t3 = time.perf_counter()
    run = {"run_id": run_id, "cases": len(cases), "computed": ex["computed"], "failed_now": ex["failed"],
           "reused": reused, "executor": _executor_name(client, strategy),
           "timings_s": {"plan": t1 - t0, "solve": t2 - t1, "metrics": t3 - t2},
           "case_timings_s": ex["timings"]}
    qtable = tidy_frame(qrows, variants)
    paths = write_outputs(outdir, model, summary, results, run, report, client, qtable)
    run["timings_s"]["total"] = time.perf_counter() - t0
    return {"summary": summary, "run": run, "paths": paths, "variants": results, "quantities": qtable}


def _import_report() -> None:
    """The report's modules (matplotlib, jinja2), imported before the local workers fork: they inherit them."""
    from ..report import sweep_report  # noqa: F401


def _executor_name(client, strategy) -> str:
    if client is None:
        return "in process"
    if isinstance(client, LocalExecutor):
        return client.name(strategy)
    try:
        n = len(client.scheduler_info().get("workers", {}))
    except Exception:
        n = None
    return f"dask ({n} workers, strategy {strategy})"


def make_summary(model: Model, variants, results: list[VariantResult], k_factors, tol, open_stiffness,
                 load_factors) -> dict:
    """The deterministic summary (no timings, no run ids): rounded to 10 significant digits."""
    meshes, recs, k_cs = [], [], [node_stiffness(build_mesh(v.model)) for v in variants]
    for v, r, kc in zip(variants, results, k_cs):
        m = v.model.mesh
        rec = variant_recommendation(v, kc, r.per_k, r.lagrange, tol)
        recs.append(rec)
        meshes.append({
            "mesh": v.label, "name": rec["name"], "grid": dict(v.grid), "n_theta": m.n_theta, "n_z": m.n_z, "n_r": m.n_r, "overrides": dict(v.overrides),
            "compared_load_factors": [] if r.comparison is None else [p.load_factor for p in r.comparison.points],
            LAGRANGE: r.lagrange, PENALTY: r.per_k, "recommended_k_factor": rec["k_factor"], "recommended": rec,
            **({AUGMENTED: r.augmented} if r.augmented else {}),
            "max_rel_diff_never_grows_with_k": monotone([d["max_rel_diff"] for d in r.per_k if not d.get("error")]),
            "errors": r.errors,
        })
    overall = overall_recommendation(k_factors, variants, k_cs, recs, [r.per_k for r in results], tol)
    pen = model.contact.penalty
    return rnd({
        "conventions": "sigma_n < 0 compression [Pa]; theta [deg] CCW from +x; differences are "
                       "sigma_n(penalty) - sigma_n(lagrange) of the through-wall mean profile per azimuth; "
                       "rel_diff = max_abs_diff / |Lagrange peak compression| at the same load factor; "
                       "liftoff_zone_iou = intersection over union of the liftoff zones; liftoff_load_factor = "
                       "bisected onset at the first table node; a k-factor is within tol when rel_diff <= tol "
                       "at every compared load factor",
        "model": model.name, "load_introduction": model.load_introduction,
        "k_factors": k_factors, "tol": tol, "open_stiffness": open_stiffness,
        "penalty_rule": (f"k_c = {pen.alpha:g} A^2 K / V per slave node" if pen.k_normal is None
                         else f"k_c = {pen.k_normal:g} N/m per slave node") + " times the k-factor; open gaps "
                        + (f"k_open = {pen.open_ratio:g} k" if open_stiffness == "scaled"
                           else f"k_open = {pen.open_ratio:g} k_c at every k"),
        "lagrange_reference": (
            "Coulomb friction with exact stick: the limit k -> infinity of the penalty cases only when their "
            "stick slope k_t follows k" if model.contact.tangential == "friction" else
            "the limit k -> infinity of the penalty cases: " + (
                "circumferential springs rigid (k_t follows k)" if pen.k_tangent_follows else
                f"the same circumferential springs, k_t = {pen.k_tangent:g} N/m")),
        "requested_load_factors": None if load_factors is None else sorted(float(x) for x in load_factors),
        "recommended_k_factor": overall["k_factor"], "recommended": overall,
        "recommended_k_factor_note": overall["note"],
        "beam_theory_liftoff_load_factor": model.beam_theory_liftoff(),
        "meshes": meshes,
        "model_definition": model.to_dict(),
    })


def sweep_frame(results: list[VariantResult]) -> pd.DataFrame:
    rows = [r for v in results for r in v.rows]
    return pd.DataFrame(rows, columns=CSV_COLUMNS)


def write_outputs(outdir, model, summary: dict, results: list[VariantResult], run: dict, report: bool,
                  client=None, quantities: pd.DataFrame | None = None) -> list[Path]:
    """summary.json, sweep.csv, quantities.csv, run.json and report.html (figures drawn on the Dask
    workers if any)."""
    names = ["summary.json", "sweep.csv", "quantities.csv", "run.json"] + (["report.html"] if report else [])
    html = None
    if report:
        from ..report.sweep_report import render_sweep
        t = time.perf_counter()
        mapper = (None if client is None else client.mapper() if isinstance(client, LocalExecutor)
                  else (lambda fn, jobs: client.gather(client.map(fn, jobs, pure=False))))
        html = render_sweep(summary, results, model, mapper=mapper, quantities=quantities)
        run["timings_s"]["report"] = time.perf_counter() - t
    with staged(outdir) as stage:
        (stage / "summary.json").write_text(json.dumps(summary, indent=2, ensure_ascii=False) + "\n", encoding="utf-8")
        sweep_frame(results).to_csv(stage / "sweep.csv", index=False, float_format="%.9g")
        (quantities if quantities is not None else pd.DataFrame()).to_csv(stage / "quantities.csv", index=False,
                                                                          float_format="%.9g")
        (stage / "run.json").write_text(json.dumps(rnd(run), indent=1) + "\n")
        if html is not None:
            (stage / "report.html").write_text(html, encoding="utf-8")
    return [Path(outdir) / n for n in names]
