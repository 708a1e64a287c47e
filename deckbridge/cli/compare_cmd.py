"""``deckbridge compare SOURCE... -o DIR``: align sources on azimuth, compare sigma_N, write the report."""

from __future__ import annotations

from pathlib import Path

import click

from ..errors import DeckbridgeError
from ..model import load
from ..readers import detect, formats
from ._common import main


@main.command("compare")
@click.argument("sources", nargs=-1, required=True, type=click.Path())
@click.option("-o", "--out", "outdir", required=True, type=click.Path(),
              help="Output folder: report.html, sigma_n.png, discrepancy.csv, summary.json (written whole or not at all).")
@click.option("--model", "model_path", type=click.Path(dir_okay=False),
              help="Neutral model the results belong to (maps node numbers to azimuth, checks node ids).")
@click.option("--set", "overrides", multiple=True, metavar="KEY=VALUE",
              help="Override a model value (repeatable); implies the default model when --model is absent.")
@click.option("--load-factor", "load_factors", multiple=True, type=float, metavar="L",
              help="Compare at load factor L (repeatable) instead of the defaults: end of step 1, first liftoff, "
                   "end of step 2.")
@click.option("--format", "formats", multiple=True, metavar="F",
              help=f"Format of the sources ({', '.join(formats())}; one for all, or one per source); default: detected.")
@click.option("--surface", type=click.Choice(["table", "stop"]), default="table", show_default=True,
              help="Contact surface whose sigma_N is compared.")
def compare_cmd(sources, outdir, model_path, overrides, load_factors, formats, surface):
    """Compare contact stresses of SOURCE... (result folders or files) and write a report to DIR."""
    # imported here, not with the CLI: the report brings matplotlib and jinja2, the reference reader the
    # solver (every other command starts without them)
    from ..compare import compare_tables
    from ..compare.onsets import describe
    from ..mesh import build_mesh
    from ..readers import read_result
    from ..report import write_report

    model = load(model_path, list(overrides)) if (model_path or overrides) else None
    if formats and len(formats) not in (1, len(sources)):
        raise DeckbridgeError(f"--format given {len(formats)} times for {len(sources)} sources: give one, or one per source")
    fmts = list(formats) * len(sources) if len(formats) == 1 else (list(formats) or [None] * len(sources))
    mesh = build_mesh(model) if model is not None else None      # the command's one mesh
    tables, inputs = [], {}
    for src, fmt in zip(sources, fmts):
        name = fmt or detect(src)
        tables.append(read_result(src, fmt=name, model=model, mesh=mesh))   # the format's record decides
        inputs[src] = name
    result = compare_tables(tables, load_factors=list(load_factors) or None, origins=list(sources), surface=surface)
    shown = {s.label: f"{s.origin} ({inputs[s.origin]})" for s in result.series}
    paths = write_report(result, outdir, model=model, extra={"inputs": shown})
    for p in paths:
        click.echo(f"wrote {p}")
    for s in result.series:
        o = result.onsets[s.label]
        click.echo(f"{s.label}: onset first node {describe(o['first_node'])}, whole section {describe(o['section'])}")
    for pair in result.primary.pairs:
        click.echo(f"lambda = {pair['load_factor']:.4g}: {pair['b']} - {pair['a']}: max |d sigma_n| = "
                   f"{pair['max_abs_diff_pa'] / 1e6:.3f} MPa at {pair['theta_of_max_diff_deg']:.1f} deg, "
                   f"liftoff-zone overlap {pair['liftoff_zone_overlap']:.3f}")
    click.echo(f"report: {Path(outdir) / 'report.html'}")
