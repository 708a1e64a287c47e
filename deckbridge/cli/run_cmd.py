"""``deckbridge run``: the main job on a model (the embedded default JAR without argument)."""

import click

from ._common import main, model_options


@main.command("run")
@model_options
@click.option("-o", "--out", "outdir", default="jar-report", show_default=True,
              type=click.Path(), help="Output folder.")
@click.option("--with-ccx", is_flag=True, help="Also run CalculiX on its penalty and mortar decks.")
def run_cmd(model, outdir, with_ccx):
    """Write the decks, solve with penalty and Lagrange, compare and write the report."""
    from ..api import run                    # decks, solver, report: imported when the job runs

    run(model, outdir, with_ccx=with_ccx, echo=click.echo)
