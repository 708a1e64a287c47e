"""``deckbridge decks``: render the solver decks of a model."""

import click

from ..render import render_all
from ._common import main, model_options


@main.command("decks")
@model_options
@click.option("-o", "--out", "outdir", required=True, type=click.Path(file_okay=False),
              help="Output folder (created; files appear whole or not at all).")
@click.option("--dialect", "dialects", multiple=True,
              help="Only these dialects (nastran, mystran, abaqus, calculix); default all.")
def decks_cmd(model, outdir, dialects):
    """Write the Nastran penalty, Abaqus Lagrange, CalculiX and MYSTRAN decks of MODEL."""
    for path in render_all(model, outdir, list(dialects) or None):
        click.echo(f"wrote {path}")
