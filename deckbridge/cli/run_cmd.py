"""``deckbridge run``: the main job on a model (the embedded default JAR without argument)."""

import click

from ..dialects import runnable
from ..methods import NAMES
from ._common import as_flags, main, model_options


@main.command("run")
@model_options
@click.option("-o", "--out", "outdir", default="jar-report", show_default=True,
              type=click.Path(), help="Output folder.")
@click.option("--with", "solvers", multiple=True, type=click.Choice(runnable()), metavar="DIALECT",
              help=f"Also run this dialect's solver on its decks and compare its results (repeatable; "
                   f"{', '.join(runnable())}).")
@click.option("--with-ccx", is_flag=True, help="Same as --with calculix: CalculiX on its penalty and mortar decks.")
@click.option("--method", "methods", type=click.Choice(NAMES), multiple=True,
              help="Reference solves (repeatable) [default: penalty and lagrange].")
def run_cmd(model, outdir, solvers, with_ccx, methods):
    """Write the decks, solve with penalty and Lagrange (or --method ...), compare and write the report."""
    from ..api import run                    # decks, solver, report: imported when the job runs

    run(model, outdir, with_ccx=with_ccx, solvers=solvers, echo=lambda line: click.echo(as_flags(line)),
        **({"methods": methods} if methods else {}))
