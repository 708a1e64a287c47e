"""``deckbridge sweep`` (penalty sensitivity against Lagrange, on forked local workers or Dask) and ``deckbridge liftoff``."""

from __future__ import annotations

import json
import os
from pathlib import Path

import click

from .. import limits
from .. import summary_keys as K
from ..errors import DeckbridgeError
from ..methods import AUGMENTED, K_METHODS, LAGRANGE, NAMES, PENALTY
from ..outdir import lock, remove_stale, staged
from ._common import main, model_options

DEFAULT_K = "0.01,0.1,1,10,100,1000"


@main.command("sweep")
@model_options
@click.option("--k-factors", "k_factors", default=DEFAULT_K, show_default=True, metavar="F1,F2,...",
              help="Penalty factors on the model's normal contact stiffness k_c.")
@click.option("-o", "--out", "outdir", required=True, type=click.Path(),
              help="Study folder: summary.json, sweep.csv, report.html, run.json and cases/ (resumable).")
@click.option("--mesh", "mesh_opts", multiple=True, metavar="KEY=V1,V2,...",
              help="Mesh variants, e.g. --mesh n_theta=60,120,240 (repeatable: the product is swept).")
@click.option("--grid", "grid_opts", multiple=True, metavar="KEY=V1,V2,...",
              help="Variants of any model key, e.g. --grid contact.penalty.open_ratio=1e-12,1e-3 --grid "
                   "contact.penalty.k_tangent=follow,1e6 (repeatable: the product is swept).")
@click.option("--claim-load-factor", "claim_lf", type=float, default=None, metavar="L",
              help="Load factor at which the paper's claims are judged [default: min(1, steps.lambda_max)].")
@click.option("--tol", type=float, default=0.02, show_default=True,
              help="Recommended k: within TOL x |Lagrange peak compression| at every compared load factor.")
@click.option("--load-factor", "load_factors", multiple=True, type=float, metavar="L",
              help="Compare at load factor L (repeatable) instead of: end of step 1, first liftoff, end of step 2.")
@click.option("--open-stiffness", type=click.Choice(["scaled", "fixed"]), default="scaled", show_default=True,
              help="Open-gap stiffness: scaled (open_ratio x k, as a PGAP KB = ratio x KA) or fixed "
                   "(open_ratio x k_c whatever the k-factor).")
@click.option("--scheduler", default=None, metavar="ADDRESS",
              help="Run on an existing Dask cluster (e.g. tcp://host:8786) instead of a local one.")
@click.option("--workers", type=int, default=None,
              help="Worker processes of the local executor or Dask cluster [default: the machine's cores].")
@click.option("--strategy", type=click.Choice(["split", "mesh"]), default="split", show_default=True,
              help="split: one condensation task per mesh, one task per case; mesh: one task per mesh.")
@click.option("--executor", type=click.Choice(["auto", "local", "dask"]), default="auto", show_default=True,
              help="local: condense here, cases on worker processes forked from this one (no cluster); dask: a "
                   "Dask cluster (local, or --scheduler); auto: local for one condensation (one mesh), else dask.")
@click.option("--augmented", is_flag=True,
              help="Also solve with the augmented Lagrangian at every k-factor (its curve against k is flat).")
def sweep_cmd(model, k_factors, outdir, mesh_opts, grid_opts, claim_lf, tol, load_factors, open_stiffness,
              scheduler, workers, strategy, executor, augmented):
    """Penalty sensitivity of MODEL: every k-factor (and mesh, and grid point) against the Lagrange
    reference, with the paper's two claims judged per variant and quantity."""
    from ..studies.cases import mesh_variants, parse_grid_options, parse_k_factors, parse_mesh_options
    from ..studies.cluster import executor_kind, open_executor
    from ..studies.sweep import check_options, run_sweep

    _check_sizes(k_factors, mesh_opts, load_factors, workers, grid_opts, augmented)   # counted before any expansion
    ks = parse_k_factors(k_factors)
    meshes = parse_mesh_options(mesh_opts)
    grid = parse_grid_options(grid_opts)
    check_options(ks, tol, open_stiffness, strategy, model, list(load_factors) + ([claim_lf] if claim_lf is not None else []))
    variants = mesh_variants(model, meshes, grid)   # a bad mesh or grid value fails here, before any work
    condensations = len({v.condense_key for v in variants})
    executor_kind(executor, scheduler, condensations)
    allow_large = click.get_current_context().meta.get("deckbridge.allow_large", False)
    n_workers = workers or (1 if scheduler else os.cpu_count() or 1)
    for v in variants:
        limits.check_memory(v.model, allow_large, copies=min(n_workers, len(ks) + 1), what=" (--mesh)")
    with lock(outdir, "another sweep"):
        remove_stale(outdir)                     # temporaries of a killed run
        with open_executor(executor, scheduler, workers, condensations) as client:
            out = run_sweep(model, ks, outdir, meshes=meshes, tol=tol, load_factors=list(load_factors) or None,
                            open_stiffness=open_stiffness, client=client, strategy=strategy, progress=True,
                            grid=grid, claim_load_factor=claim_lf, augmented=augmented)
    s, run = out["summary"], out["run"]
    click.echo(f"{len(run['computed'])} cases computed, {len(run['reused'])} reused from {Path(outdir) / 'cases'}"
               + (f", {len(run['failed_now'])} failed" if run["failed_now"] else "")
               + f" ({run['executor']})")
    for m in s["meshes"]:
        lag = m[LAGRANGE]
        if m.get("grid"):
            click.echo("grid " + " ".join(f"{k}={'follow' if v is None else v}" for k, v in m["grid"].items()))
        click.echo(f"mesh {m['mesh']}: Lagrange liftoff lambda = {_f(lag.get('liftoff_load_factor'))}")
        click.echo(f"  {'k-factor':>9} {'max|dsig| MPa':>14} {'% of peak':>10} {'IoU':>6} {'peak MPa':>9} "
                   f"{'liftoff':>8} {'within tol':>10} {K.ONSET_REL_DIFF + ' %':>16} {K.REPRODUCES}")
        for d in m[PENALTY]:
            if d.get("error"):
                click.echo(f"  {d['k_factor']:>9g}  failed: {d['error']}")
                continue
            click.echo(f"  {d['k_factor']:>9g} {d['max_abs_diff_pa'] / 1e6:>14.3f} {d['max_rel_diff'] * 100:>10.2f} "
                       f"{d['liftoff_zone_iou']:>6.3f} {d['peak_compression_pa'] / 1e6:>9.2f} "
                       f"{_f(d['liftoff_load_factor']):>8} {'yes' if d['within_tol'] else 'no':>10} "
                       f"{_onset(d, lag):>16} {'yes' if d.get(K.REPRODUCES) else 'no'}")
        for d in m.get(AUGMENTED, []):
            click.echo(f"  {d['k_factor']:>9g}  augmented: " + (f"failed: {d['error']}" if d.get("error") else
                       f"{d['max_abs_diff_pa'] / 1e6:.3g} MPa ({d['max_rel_diff'] * 100:.2g} % of peak) from Lagrange, "
                       f"liftoff {_f(d['liftoff_load_factor'])}"))
        if not m.get("max_rel_diff_never_grows_with_k"):
            click.echo("  note: max |dsig| grows again at large k (open gaps carry k_open x gap; "
                       "try --open-stiffness fixed or a smaller contact.penalty.open_ratio)")
    for line in claims_lines(s.get("claims") or []):
        click.echo(line)
    rec = s["recommended_k_factor"]
    click.echo("recommended k-factor: " + (f"{rec:g}" if rec is not None else "none") + f" ({s['recommended_k_factor_note']})")
    for p in out["paths"]:
        click.echo(f"wrote {p}")


def claims_lines(claims: list[dict]) -> list[str]:
    """The claims' verdicts, one line per variant and quantity."""
    out = []
    for c in claims:
        if c.get("error"):
            out.append(f"claims [{c['variant']}]: no Lagrange reference ({c['error']})")
            continue
        on = c["onsets"]
        out.append(f"claims at lambda = {c['load_factor']:.4g} [{c['grid_label'] or c['mesh']}]: onsets first node / "
                   f"whole section: Lagrange {_f(on[LAGRANGE]['first_node'])} / {_f(on[LAGRANGE]['whole_section'])}; "
                   + ", ".join(f"k={p['k_factor']:g} {_f(p['first_node'])} / {_f(p['whole_section'])}" for p in on[PENALTY]))
        for q, v1 in c["claim1"].items():
            v2 = c["claim2"][q]
            mx = max((d["max_in_lifted_pa"] for d in v1[PENALTY] if d["max_in_lifted_pa"] is not None), default=None)
            out.append(f"  {q:<16} claim 1 {'holds' if v1['holds'] else 'no   '} (penalty max in lifted zones "
                       f"{_mpa(mx)} MPa, Lagrange max {_mpa(v1['lagrange_max_pa'])} MPa); claim 2: peak |sigma| "
                       f"{v2['direction']} with k ({', '.join(_mpa(x) for x in v2['peak_abs_pa'])} MPa; Lagrange "
                       f"{_mpa(v2['lagrange_peak_abs_pa'])}), reproduces Lagrange at k = "
                       f"{', '.join(f'{k:g}' for k in v2['reproduces_lagrange_at_k']) or 'none'}")
        if c["k_tangent_follows_k"]:
            out.append(f"  note: {c['lagrange_depends_on_alpha_note']}")
    return out


def _mpa(v) -> str:
    return "-" if v is None else f"{v / 1e6:.3g}"


def _check_sizes(k_factors: str, mesh_opts, load_factors, workers, grid_opts=(), augmented: bool = False) -> None:
    """Caps on the size of a study, from the option text alone (nothing expanded yet)."""
    n_k = str(k_factors).count(",") + 1
    limits.check_count("--k-factors", n_k, limits.MAX_K_FACTORS, "k-factors")
    n_mesh = 1
    for opt in mesh_opts:
        n_mesh *= opt.count(",") + 1
        limits.check_count("--mesh", n_mesh, limits.MAX_MESH_VARIANTS, "mesh variants")
    n_grid = 1
    for opt in grid_opts:
        n_grid *= opt.count(",") + 1
        limits.check_count("--grid", n_grid, limits.MAX_GRID_CASES, "grid cases")
    per_variant = (2 if augmented else 1) * n_k + 1           # Lagrange, penalty (and augmented) per k-factor
    limits.check_count("--k-factors x --mesh x --grid", n_grid * n_mesh * per_variant, limits.MAX_CASES, "cases")
    limits.check_count("--load-factor", len(load_factors), limits.MAX_LOAD_FACTORS, "load factors")
    limits.check_workers(workers)


def _onset(d: dict, lag: dict) -> str:
    """The onset difference of a penalty row in % of the Lagrange onset ('one lifts' when only one method lifts
    off: summary.json holds null there, as for a failed case)."""
    v = d.get(K.ONSET_REL_DIFF)
    if v is not None:
        return f"{v * 100:.2f}"
    return "one lifts" if (d.get("liftoff_load_factor") is None) != (lag.get("liftoff_load_factor") is None) else "-"


def _f(v) -> str:
    return "none" if v is None else f"{v:.4f}"


@main.command("liftoff")
@model_options
@click.option("--method", type=click.Choice([*NAMES, "both"]), default="both", show_default=True,
              help="Contact method (deckbridge.methods) or both (penalty and lagrange, their difference printed).")
@click.option("--tol", type=float, default=1e-3, show_default=True,
              help="Tolerance on the critical load factor (absolute, in lambda).")
@click.option("--k-factor", "k_factor", type=float, default=None,
              help="Penalty: factor on the model's normal contact stiffness [default: 1].")
@click.option("-o", "--out", "outdir", default=None, type=click.Path(),
              help="Also write DIR/summary.json (per method lambda_c and theta_deg).")
def liftoff_cmd(model, method, tol, k_factor, outdir):
    """Critical load factor lambda_c (on T and M in step 2) at which liftoff begins, and where."""
    from ..api import liftoff
    from ..studies.liftoff import format_table
    from ..studies.metrics import rnd

    methods = (PENALTY, LAGRANGE) if method == "both" else (method,)
    if k_factor is not None and not any(m in K_METHODS for m in methods):
        raise DeckbridgeError(f"--k-factor = {k_factor!r}: only for --method {', '.join(K_METHODS)} or both")
    res = liftoff(model, methods, tol=tol, k_factor=1.0 if k_factor is None else k_factor).summary
    click.echo(format_table(res))
    if outdir is not None:
        with staged(outdir) as stage:
            (stage / "summary.json").write_text(json.dumps(rnd(res), indent=2) + "\n")
        click.echo(f"wrote {Path(outdir) / 'summary.json'}")
