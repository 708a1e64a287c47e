"""``deckbridge decks``: render the solver decks of a model."""

import click

from ..dialects import names
from ._common import as_flags, main, model_options


@main.command("decks")
@model_options
@click.option("-o", "--out", "outdir", required=True, type=click.Path(),
              help="Output folder (created; files appear whole or not at all).")
@click.option("--dialect", "dialects", multiple=True,
              help=f"Only these dialects ({', '.join(names())}); default all.")
def decks_cmd(model, outdir, dialects):
    """Write the solver decks of MODEL (every dialect of deckbridge.dialects, or those of --dialect).

    Without --dialect a dialect that cannot carry the model is left out with a note (as ``run`` does); a
    dialect named with --dialect that cannot is an error.
    """
    from ..render import render_all          # jinja2: imported by the commands that render only

    skip = None if dialects else (lambda exc: click.echo(as_flags(exc.note())))
    for path in render_all(model, outdir, list(dialects) or None, on_unsupported=skip):
        click.echo(f"wrote {path}")
